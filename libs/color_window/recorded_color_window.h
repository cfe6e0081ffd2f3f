// The part of the colour sensor a recording holds, and the calibration it stores for it:
// the calibrated image whole, or the window the first frame's camera read out (a region
// of interest, ColorImage::sensor_offset), which every later frame must then be. Replay
// uses the stored calibration as any recording's own, so windowed frames register as
// they did live.
#pragma once

#include <optional>
#include <string>

#include <opencv2/core/types.hpp>

#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"

namespace tilth {

class RecordedColorWindow {
 public:
  explicit RecordedColorWindow(RigCalibration calibration);

  // Takes the window of the recording's first frame, replacing that of a first frame the
  // recorder then refused. Throws tilth::Error ("color: ...") when the window's
  // calibration would not be read back (a principal point outside it, a field of view
  // under a degree).
  void begin(const ColorImage& color);
  // Throws tilth::Error ("color: ...") unless `color` is the first frame's window.
  void check(const ColorImage& color) const;

  cv::Size size() const { return window_.size(); }
  bool whole() const { return !windowed_; }
  // The calibration the recording stores: the given one, or its window's.
  const RigCalibration& calibration() const { return windowed_ ? *windowed_ : calibration_; }

 private:
  cv::Rect window_of(const ColorImage& color) const;

  const RigCalibration calibration_;
  cv::Rect window_;
  std::optional<RigCalibration> windowed_;
};

}  // namespace tilth
