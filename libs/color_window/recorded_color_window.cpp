#include "recorded_color_window.h"

#include <utility>

#include "tilth/error.h"

namespace tilth {
namespace {

std::string describe(const cv::Rect& window) {
  return "the sensor's " + std::to_string(window.width) + "x" + std::to_string(window.height) +
         " px at (" + std::to_string(window.x) + ", " + std::to_string(window.y) + ")";
}

}  // namespace

RecordedColorWindow::RecordedColorWindow(RigCalibration calibration)
    : calibration_(std::move(calibration)),
      window_(0, 0, calibration_.color.width, calibration_.color.height) {}

cv::Rect RecordedColorWindow::window_of(const ColorImage& color) const {
  return color.sensor_offset ? color.sensor_window()
                             : cv::Rect(0, 0, calibration_.color.width, calibration_.color.height);
}

void RecordedColorWindow::begin(const ColorImage& color) {
  const cv::Rect window = window_of(color);
  windowed_.reset();
  window_ = cv::Rect(0, 0, calibration_.color.width, calibration_.color.height);
  if (window == window_) return;
  RigCalibration windowed = with_color_window(calibration_, window);
  try {
    parse_calibration(to_json(windowed), windowed.origin);
  } catch (const Error& error) {
    throw Error("color: the calibration of " + describe(window) +
                " cannot be recorded: " + error.what());
  }
  windowed_ = std::move(windowed);
  window_ = window;
}

void RecordedColorWindow::check(const ColorImage& color) const {
  const cv::Rect window = window_of(color);
  if (window != window_) {
    throw Error("color: " + describe(window) + "; expected " + describe(window_) +
                " as in the first frame (a recording has one colour window)");
  }
}

}  // namespace tilth
