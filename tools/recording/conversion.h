// `tilth recording export` and `import`: an MCAP recording to an image-folder recording
// and back, each by running the recording stages in a graph of their own (player ->
// writer), so the formats are read and written by the same code as in `tilth run`. The
// players are asked for the recorded host capture times (host_time: recorded), so those
// carry through as every other field does.
#pragma once

#include <filesystem>
#include <string>

#include "framework/runtime.h"

namespace tilth::tools {

struct ConversionOptions {
  bool overwrite = false;   // replace an existing output that is a recording
  std::string compression;  // import: the MCAP chunk compression; "" = mcap.writer's default
};

// mcap.player -> recording.image_folder_writer, with the calibration the MCAP file
// carries. Returns the run (frames written: metrics.frames_completed; a stop signal ends
// it early with a complete output); throws tilth::Error (or GraphError) saying what and
// where.
RunResult export_to_folder(const std::filesystem::path& mcap_file,
                           const std::filesystem::path& folder, const ConversionOptions& options);

// recording.image_folder -> mcap.writer, with the calibration recording.json names
// (a file, or an inline object).
RunResult import_from_folder(const std::filesystem::path& folder,
                             const std::filesystem::path& mcap_file,
                             const ConversionOptions& options);

}  // namespace tilth::tools
