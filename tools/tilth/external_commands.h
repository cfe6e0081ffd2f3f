// Commands that live in their own executables, as git's do: `tilth NAME ARGS` runs
// `tilth-NAME ARGS`, found next to the `tilth` executable or on PATH. Plugin families ship
// their tools this way (`tilth cameras`, `tilth recording`), so this program knows none of
// them by name.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace tilth::cli {

// Replaces this process with `tilth-NAME`; returns only if there is no such command.
// Throws tilth::Error when it exists but cannot be started.
void exec_external_command(const std::string& name, int argc, char** argv);

// The NAMEs of the `tilth-NAME` executables found, sorted, each once.
std::vector<std::string> external_commands();

}  // namespace tilth::cli
