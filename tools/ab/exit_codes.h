// The exit codes of `tilth ab` and `tilth ab merge` (docs/ab-testing.md).
#pragma once

namespace tilth::ab {

constexpr int kExitOk = 0;
constexpr int kExitFailed = 1;  // a graph failed, a job is missing, or nothing was written
constexpr int kExitUsage = 2;   // a mistake on the command line; nothing ran

}  // namespace tilth::ab
