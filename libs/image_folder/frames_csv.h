// frames.csv of an image-folder recording: the whole index read and checked at once,
// the lines the writer appends, and the mask column rewritten when masks are imported.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace tilth::recording {

// The header the writer writes: every column, in the spec's order.
inline constexpr std::string_view kFramesCsvHeader =
    "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm";

// What a frames.csv may hold: 1 000 000 frames is over 9 hours at 30 frames/s (and
// about 4.5 TB of PNGs at the paper rig's sizes), and 128 MiB and lines of 16 KiB leave
// room for long paths.
inline constexpr std::size_t kMaxFrames = 1'000'000;
inline constexpr std::uint64_t kMaxFramesCsvBytes = 128 << 20;
inline constexpr std::size_t kMaxFramesCsvLine = 16 << 10;

struct FrameEntry {
  std::size_t line = 0;  // in frames.csv, counting the header as line 1
  std::uint64_t index = 0;
  std::int64_t depth_timestamp_ns = 0;
  std::int64_t color_timestamp_ns = 0;
  std::string depth;  // paths relative to the recording folder
  std::string color;
  std::string mask;  // empty: no mask
  std::optional<double> ground_truth_mm;
};

// Reads every line; throws tilth::Error naming the file, the line and what was expected
// for a missing or unknown column, a malformed or out-of-range field, an index or
// timestamp that does not increase, or a file beyond the limits above (or not a regular
// file).
std::vector<FrameEntry> read_frames_csv(const std::filesystem::path& file);

// One line of frames.csv, without the newline, in kFramesCsvHeader's column order.
std::string frames_csv_line(const FrameEntry& entry);

// A frame's file name in depth/, color/ and mask/: its index, six digits or more
// ("000012.png").
std::string frame_file_name(std::uint64_t index);

// Replaces the `mask` field of the lines of `file` (a frames.csv read_frames_csv has
// accepted) that `masks` names by line number (FrameEntry::line), adding the column at
// the end of every line when the file has none; every other byte stays as it was. Writes
// FILE.new beside it and renames it over `file`, so a reader sees the old index or the
// new one, never a mix. Throws tilth::Error naming the file when it cannot be read or
// written.
void rewrite_mask_column(const std::filesystem::path& file,
                         const std::map<std::size_t, std::string>& masks);

}  // namespace tilth::recording
