#include "camera_geometry/lens_model.h"

#include <cmath>
#include <sstream>

#include <opencv2/calib3d.hpp>

#include "tilth/error.h"

namespace tilth::lens {
namespace {

// OpenCV inverts the model by fixed-point iteration; these let it run to well below a
// hundredth of a pixel, and anything it leaves above kMaxResidualPx is refused.
constexpr int kMaxIterations = 100;
constexpr double kTargetResidualPx = 1e-6;
constexpr double kMaxResidualPx = 1e-3;

}  // namespace

std::vector<cv::Point2d> undistort(const CameraIntrinsics& camera,
                                   const std::vector<cv::Point2d>& pixels,
                                   const std::string& where) {
  std::vector<cv::Point2d> normalised(pixels.size());
  if (!camera.has_distortion()) {
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      normalised[i] = {(pixels[i].x - camera.cx) / camera.fx,
                       (pixels[i].y - camera.cy) / camera.fy};
    }
    return normalised;
  }
  if (pixels.empty()) return normalised;
  const std::vector<double> coefficients(camera.distortion.begin(), camera.distortion.end());
  cv::undistortPoints(pixels, normalised, camera.camera_matrix(), coefficients, cv::noArray(),
                      cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                       kMaxIterations, kTargetResidualPx));
  const Distortion<double> model = distortion_of(camera);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    double x = normalised[i].x;
    double y = normalised[i].y;
    model.apply(x, y);
    const double residual_px = std::hypot(camera.fx * x + camera.cx - pixels[i].x,
                                          camera.fy * y + camera.cy - pixels[i].y);
    if (!(residual_px <= kMaxResidualPx)) {
      std::ostringstream message;
      message << where << ": the lens distortion cannot be inverted at pixel (" << pixels[i].x
              << ", " << pixels[i].y << "): the undistorted point maps back " << residual_px
              << " px away; expected coefficients whose model is invertible over the image";
      throw Error(message.str());
    }
  }
  return normalised;
}

cv::Mat undistorted_pixel_grid(const CameraIntrinsics& camera, const std::string& where) {
  std::vector<cv::Point2d> pixels;
  pixels.reserve(static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height));
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) pixels.emplace_back(u, v);
  }
  return cv::Mat(undistort(camera, pixels, where), true).reshape(2, camera.height);
}

}  // namespace tilth::lens
