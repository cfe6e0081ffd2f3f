// The part of the colour sensor a recording's images hold: the whole calibrated image, or
// the window the first recorded frame's camera read out (a region of interest,
// ColorImage::sensor_offset), which every later frame must then be. A recording stores the
// rig's calibration as it is and the window beside it, and replay gives its images their
// sensor_offset again, so that they register as they did live.
#pragma once

#include <optional>

#include <opencv2/core/types.hpp>

#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"

namespace tilth {

class RecordedColorWindow {
 public:
  explicit RecordedColorWindow(const CameraIntrinsics& color);

  // The sensor pixels `color` holds. Throws tilth::Error ("color: ...") when they are not
  // inside the calibrated image, or not the window of the frames recorded before.
  cv::Rect check(const ColorImage& color) const;
  // The recording's window from its first recorded frame on.
  void take(const cv::Rect& window) { taken_ = window; }
  // What the recording stores beside the calibration: the window, unless the images are
  // the whole calibrated image.
  std::optional<cv::Rect> stored() const;

 private:
  const cv::Rect whole_;
  std::optional<cv::Rect> taken_;
};

}  // namespace tilth
