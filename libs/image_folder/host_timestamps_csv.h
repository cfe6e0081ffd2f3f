// host_timestamps.csv: each frame's host capture time (CLOCK_REALTIME, ns), which the
// image-folder format has no column for. A Tilth extension that other readers ignore:
// one line per line of frames.csv, in the same order, read and checked at once.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "image_folder/frames_csv.h"

namespace tilth::recording {

inline constexpr std::string_view kHostTimestampsFile = "host_timestamps.csv";
inline constexpr std::string_view kHostTimestampsHeader = "index,host_timestamp_ns";

// The host capture time of each of `frames`, in their order. Throws tilth::Error naming
// the file, the line and what was expected for a wrong header, a malformed field, an
// index that is not the one of the same frame in frames.csv, or a missing line. One line
// after the last frame is ignored: a writer killed between the two files wrote it.
std::vector<std::int64_t> read_host_timestamps(const std::filesystem::path& file,
                                               const std::vector<FrameEntry>& frames);

// One line, without the newline.
std::string host_timestamps_line(std::uint64_t index, std::int64_t host_timestamp_ns);

}  // namespace tilth::recording
