// The `tilth` subcommands. Each returns the process exit code: 0 success, 1 the run
// failed, 2 bad usage or an invalid graph, 3 the run ended but a stage lost data.
#pragma once

namespace tilth::cli {

int run_command(int argc, char** argv);
int validate_command(int argc, char** argv);
int plugins_command(int argc, char** argv);
int describe_command(int argc, char** argv);
int dot_command(int argc, char** argv);

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;
constexpr int kExitUsage = 2;
constexpr int kExitDataLost = 3;

}  // namespace tilth::cli
