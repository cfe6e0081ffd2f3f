#include "recorded_color_window.h"

#include <string>

#include "tilth/error.h"

namespace tilth {

RecordedColorWindow::RecordedColorWindow(const CameraIntrinsics& color)
    : whole_(0, 0, color.width, color.height) {}

cv::Rect RecordedColorWindow::check(const ColorImage& color) const {
  const cv::Rect window = color.sensor_offset ? color.sensor_window() : whole_;
  if ((window & whole_) != window) {
    throw Error("color: the sensor's " + window_text(window) + " is not inside the calibration's " +
                std::to_string(whole_.width) + "x" + std::to_string(whole_.height) +
                " px colour image");
  }
  if (taken_ && window != *taken_) {
    throw Error("color: the sensor's " + window_text(window) + "; expected " +
                window_text(*taken_) +
                " as in the first frame (a recording has one colour window)");
  }
  return window;
}

std::optional<cv::Rect> RecordedColorWindow::stored() const {
  if (!taken_ || *taken_ == whole_) return std::nullopt;
  return taken_;
}

}  // namespace tilth
