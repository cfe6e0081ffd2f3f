// Runs a helper program of tilth train-segmenter (the CNN's Python training) to its end:
// started by pid with posix_spawn, its standard output and error relayed line by line to
// this program's standard output up to a bound, and the last lines kept to say why it
// failed.
#pragma once

#include <string>
#include <vector>

namespace tilth::train_segmenter {

struct ChildResult {
  int exit_code = 0;       // the program's exit code, or 128 + the signal that ended it
  std::string last_lines;  // its last output lines (at most kKeptLines)
};

inline constexpr int kKeptLines = 20;
// Beyond this many bytes relayed, the rest of the output is read but not shown.
inline constexpr std::size_t kRelayedBytes = 1 << 20;

// `argv[0]` is the program's path. Each relayed line is prefixed with `prefix`. Throws
// tilth::Error when the program cannot be started (naming it and why).
ChildResult run_child(const std::vector<std::string>& argv, const std::string& prefix);

}  // namespace tilth::train_segmenter
