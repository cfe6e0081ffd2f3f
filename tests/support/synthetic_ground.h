// Soil-depth images of ground planes with a known distance and tilt as a calibrated ToF
// camera sees them, with range noise and outliers: inputs whose right answers are known
// in closed form, for the estimation tests and benchmarks.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <opencv2/core.hpp>

#include "camera_geometry/lens_model.h"
#include "tilth/calibration.h"

namespace tilth::testing {

struct GroundScene {
  double distance_mm = 518.0;  // mounting surface to the plane along the optical axis
  double tilt_x_deg = 0.0;     // atan(dZ/dY), as estimation.ground_plane reports it
  double tilt_y_deg = 0.0;     // atan(dZ/dX)
  double noise_mm = 0.0;       // standard deviation of Gaussian depth noise
  double outlier_fraction = 0.0;
  // Outliers lie this much nearer than the plane: residue taken for soil, mixed pixels.
  double outlier_min_mm = 20.0;
  double outlier_max_mm = 80.0;
  std::uint64_t seed = 1;
};

inline double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// A depth image of `size` (CV_32FC1, mm) of a plane 518 mm away at the middle column,
// tilted 5 degrees along the rows (0.09 mm a pixel at about 1.1 mm a pixel), with
// Gaussian noise of `sigma_mm`: no camera model, for the tests of noise measures.
inline cv::Mat noisy_tilted_plane(cv::Size size, double sigma_mm, std::uint64_t seed) {
  cv::Mat depth(size, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      depth.at<float>(v, u) = static_cast<float>(518.0 + 0.09 * (u - size.width / 2));
    }
  }
  cv::Mat noise(depth.size(), CV_32FC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma_mm);
  return depth + noise;
}

// The plane's mounting-surface distance (Z - z_offset) at camera-frame (X, Y).
inline double plane_distance_at(const GroundScene& scene, double x_mm, double y_mm) {
  return scene.distance_mm + std::tan(radians(scene.tilt_y_deg)) * x_mm +
         std::tan(radians(scene.tilt_x_deg)) * y_mm;
}

// The depth image (CV_32FC1, mm from the mounting surface along the optical axis) of
// `scene` on `camera`'s pixel grid; `outliers`, when given, is 255 where an outlier is.
inline cv::Mat render(const GroundScene& scene, const DepthCameraCalibration& camera,
                      cv::Mat* outliers = nullptr) {
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) pixels.emplace_back(u, v);
  }
  const std::vector<cv::Point2d> rays = lens::undistort(camera, pixels, "the test camera");

  const double slope_x = std::tan(radians(scene.tilt_y_deg));
  const double slope_y = std::tan(radians(scene.tilt_x_deg));
  const double axis_depth = scene.distance_mm + camera.z_offset_mm;
  cv::RNG random(scene.seed);
  cv::Mat depth(camera.height, camera.width, CV_32FC1);
  cv::Mat outlier_mask(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const cv::Point2d ray = rays[static_cast<std::size_t>(v * camera.width + u)];
      // Z = Z0 + sx X + sy Y with X = x' Z, Y = y' Z.
      const double z = axis_depth / (1.0 - slope_x * ray.x - slope_y * ray.y);
      double mm = z - camera.z_offset_mm + random.gaussian(scene.noise_mm);
      if (random.uniform(0.0, 1.0) < scene.outlier_fraction) {
        mm -= random.uniform(scene.outlier_min_mm, scene.outlier_max_mm);
        outlier_mask.at<std::uint8_t>(v, u) = 255;
      }
      depth.at<float>(v, u) = static_cast<float>(mm);
    }
  }
  if (outliers != nullptr) *outliers = outlier_mask;
  return depth;
}

}  // namespace tilth::testing
