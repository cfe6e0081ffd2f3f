// The window of the colour sensor an MCAP recording's images hold, when the camera read
// out a region of interest: metadata "tilth.color_window" (keys x, y, width, height, in
// pixels of the calibrated image), which mcap.writer adds with the first frame and
// mcap.player gives back to each image as its sensor_offset.
#pragma once

#include <optional>

#include <opencv2/core/types.hpp>

#include "mcap/mcap_format.h"
#include "mcap/mcap_reader.h"
#include "tilth/calibration.h"

namespace tilth::mcap {

inline constexpr std::string_view kColorWindowMetadata = "tilth.color_window";

Metadata color_window_metadata(const cv::Rect& window);

// The recording's window; none when it has no such metadata. Throws tilth::Error naming
// the file when the record is malformed or the window not inside `color`'s image.
std::optional<cv::Rect> read_color_window(McapReader& reader, const CameraIntrinsics& color);

}  // namespace tilth::mcap
