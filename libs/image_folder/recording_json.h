// recording.json of an image-folder recording (spec: tilth-image-folder/1): reading and
// checking it, writing it, and the colour formats the format allows.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>

#include <opencv2/core/types.hpp>

#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"

namespace tilth::recording {

inline constexpr std::string_view kFormat = "tilth-image-folder/1";

struct RecordingJson {
  RigCalibration calibration;
  PixelFormat color_format = PixelFormat::kBgr8;
  std::string description;
  std::map<std::string, std::string> tags;  // conditions it was recorded in: site, crop, ...
  // The window of the colour sensor the images hold, when the camera read out a region of
  // interest; the calibration is the whole image's.
  std::optional<cv::Rect> color_window;
};

// Reads <folder>/recording.json, and the calibration file it names; throws tilth::Error
// naming the file and field and what was expected.
RecordingJson read_recording_json(const std::filesystem::path& folder);

// Writes <folder>/recording.json (through a temporary file, so it is never half-written),
// referring to the calibration by its file name in the folder.
void write_recording_json(const std::filesystem::path& folder, const std::string& calibration_file,
                          PixelFormat color_format, const std::string& description,
                          const std::optional<cv::Rect>& color_window = std::nullopt);

// bgr8 and the four Bayer mosaics; rgb8 and mono8 are not recording formats.
bool is_recording_color_format(PixelFormat format);
std::string recording_color_formats();  // "bgr8, bayer_rggb8, ..."

}  // namespace tilth::recording
