// What a tool checks before it writes a recording: it never writes into, over or around
// its input, and an existing output is replaced only when the user said --overwrite and
// it is recognisably a recording of the kind being written.
#pragma once

#include <filesystem>

namespace tilth::tools {

enum class RecordingKind { kMcapFile, kImageFolder };

// Throws tilth::Error when `output` exists and may not be replaced: without `overwrite`
// anything but an empty folder; with it, anything that is not a recording of `kind` (a
// file that starts with MCAP's magic bytes, or an empty one; a folder with a
// recording.json).
void check_output_path(const std::filesystem::path& output, RecordingKind kind, bool overwrite);

// Throws tilth::Error when `output` is `input`, holds it, or lies inside it.
void check_apart(const std::filesystem::path& input, const std::filesystem::path& output);

}  // namespace tilth::tools
