#include "region_window.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "camera_geometry/lens_model.h"
#include "tilth/error.h"

namespace tilth {
namespace {

// Ground distances looked at, evenly spaced in 1 / distance (the parallax goes with 1 /
// (distance + z_offset_mm); the two ends, where the window's edges lie, are exact).
constexpr int kDistances = 8;
// Sampling reads around the point: the nearest pixel's 2x2 Bayer quad, or the four
// pixels bilinear interpolation blends.
constexpr int kSamplingMarginPx = 2;

std::string mm_text(double mm) {
  std::ostringstream text;
  text << mm << " mm";
  return text.str();
}

int round_down(int value, int step) { return value / step * step; }
int round_up(int value, int step) { return (value + step - 1) / step * step; }

}  // namespace

cv::Rect color_window_for(const RigCalibration& rig, const cv::Rect& depth_region, double near_mm,
                          double far_mm, int step) {
  if (!(near_mm > 0 && far_mm >= near_mm)) {
    throw Error("ground distances " + mm_text(near_mm) + " to " + mm_text(far_mm) +
                "; expected 0 < near <= far");
  }
  if (step < 1) throw Error("window step " + std::to_string(step) + " px; expected >= 1");
  const cv::Rect depth_image(0, 0, rig.depth.width, rig.depth.height);
  if (depth_region.empty() || (depth_region & depth_image) != depth_region) {
    throw Error("the depth region " + window_text(depth_region) + " is not inside the " +
                std::to_string(rig.depth.width) + "x" + std::to_string(rig.depth.height) +
                " px depth image");
  }
  std::vector<cv::Point2d> pixels;
  pixels.reserve(static_cast<std::size_t>(depth_region.area()));
  for (int v = depth_region.y; v < depth_region.y + depth_region.height; ++v) {
    for (int u = depth_region.x; u < depth_region.x + depth_region.width; ++u) {
      pixels.emplace_back(u, v);
    }
  }
  const std::vector<cv::Point2d> rays =
      lens::undistort(rig.depth, pixels, rig.origin + ":/depth_camera/distortion");
  const lens::Distortion<double> distortion = lens::distortion_of(rig.color);
  const cv::Rect sensor(0, 0, rig.color.width, rig.color.height);
  double left = std::numeric_limits<double>::max();
  double top = left;
  double right = std::numeric_limits<double>::lowest();
  double bottom = right;
  for (int i = 0; i < kDistances; ++i) {
    const double inverse = 1.0 / near_mm + (1.0 / far_mm - 1.0 / near_mm) * i / (kDistances - 1);
    const double z = 1.0 / inverse + rig.depth.z_offset_mm;
    for (const cv::Point2d& ray : rays) {
      const cv::Vec3d point =
          rig.depth_to_color_r * cv::Vec3d(ray.x * z, ray.y * z, z) + rig.depth_to_color_t_mm;
      if (point[2] <= 0) continue;
      double x = point[0] / point[2];
      double y = point[1] / point[2];
      distortion.apply(x, y);
      const double u = rig.color.fx * x + rig.color.cx;
      const double v = rig.color.fy * y + rig.color.cy;
      if (u < -0.5 || v < -0.5 || u >= sensor.width - 0.5 || v >= sensor.height - 0.5) continue;
      left = std::min(left, u);
      right = std::max(right, u);
      top = std::min(top, v);
      bottom = std::max(bottom, v);
    }
  }
  if (left > right) {
    throw Error("the depth region " + window_text(depth_region) +
                " sees none of the colour image with the ground " + mm_text(near_mm) + " to " +
                mm_text(far_mm) + " away (calibration " + rig.origin + ")");
  }
  const int x0 =
      round_down(std::max(0, static_cast<int>(std::floor(left)) - kSamplingMarginPx), step);
  const int y0 =
      round_down(std::max(0, static_cast<int>(std::floor(top)) - kSamplingMarginPx), step);
  const int x1 = std::min(
      sensor.width, round_up(static_cast<int>(std::ceil(right)) + kSamplingMarginPx + 1, step));
  const int y1 = std::min(
      sensor.height, round_up(static_cast<int>(std::ceil(bottom)) + kSamplingMarginPx + 1, step));
  return {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace tilth
