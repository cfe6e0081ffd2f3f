// Reading a whole file that a recording or configuration names, safely: only a regular
// file (a FIFO or a device would block or never end), and only up to a size limit checked
// before anything is read.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace tilth {

// The file's bytes. Throws tilth::Error naming the file when it cannot be opened, is
// not a regular file, or holds more than `max_bytes`; `what` says what it should be
// ("frames.csv", "PNG image").
std::string read_regular_file(const std::filesystem::path& file, std::uint64_t max_bytes,
                              std::string_view what);

}  // namespace tilth
