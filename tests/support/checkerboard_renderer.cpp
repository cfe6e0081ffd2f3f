#include "checkerboard_renderer.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "camera_geometry/lens_model.h"

namespace tilth::testing {
namespace {

constexpr double kBlack = 0.05;
constexpr double kWhite = 0.85;
constexpr double kBackground = 0.35;
constexpr int kEdgeSteps = 16;  // points per polygon edge, for the distortion's curvature
constexpr int kFractionBits = 8;

// A board point in the camera's pixels (0-based, pixel centres at integers).
cv::Point2d project(const CameraIntrinsics& camera, const cv::Matx33d& rotation,
                    const cv::Vec3d& translation, const cv::Vec3d& board_point) {
  const cv::Vec3d p = rotation * board_point + translation;
  double x = p[0] / p[2];
  double y = p[1] / p[2];
  lens::distortion_of(camera).apply(x, y);
  return {camera.fx * x + camera.cx, camera.fy * y + camera.cy};
}

struct Camera {
  const CameraIntrinsics& intrinsics;
  cv::Matx33d rotation;
  cv::Vec3d translation;
  int supersampling;

  // The board rectangle [x0, x1] x [y0, y1] (mm) as a polygon in the supersampled image,
  // in fixed point: supersampled pixel centres at integers, U = (u + 0.5) * s - 0.5.
  std::vector<cv::Point> polygon(double x0, double y0, double x1, double y1) const {
    const cv::Vec2d corners[4] = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
    std::vector<cv::Point> points;
    for (int side = 0; side < 4; ++side) {
      const cv::Vec2d from = corners[side];
      const cv::Vec2d to = corners[(side + 1) % 4];
      for (int step = 0; step < kEdgeSteps; ++step) {
        const cv::Vec2d at = from + (to - from) * (static_cast<double>(step) / kEdgeSteps);
        const cv::Point2d pixel = project(intrinsics, rotation, translation, {at[0], at[1], 0.0});
        points.emplace_back(
            cvRound(((pixel.x + 0.5) * supersampling - 0.5) * (1 << kFractionBits)),
            cvRound(((pixel.y + 0.5) * supersampling - 0.5) * (1 << kFractionBits)));
      }
    }
    return points;
  }
};

}  // namespace

cv::Mat render_reflectance(const CameraIntrinsics& camera, const cv::Matx33d& rotation,
                           const cv::Vec3d& translation_mm, const Checkerboard& board,
                           int supersampling) {
  const Camera view{camera, rotation, translation_mm, supersampling};
  const double s = board.square_mm;
  const int squares_x = board.inner_corners.width + 1;
  const int squares_y = board.inner_corners.height + 1;
  constexpr double kLevels = 65535.0;
  cv::Mat fine(camera.height * supersampling, camera.width * supersampling, CV_16U,
               cv::Scalar(kBackground * kLevels));
  const double m = board.margin_mm;
  cv::fillPoly(
      fine,
      std::vector{view.polygon(-s - m, -s - m, (squares_x - 1) * s + m, (squares_y - 1) * s + m)},
      cv::Scalar(kWhite * kLevels), cv::LINE_8, kFractionBits);
  std::vector<std::vector<cv::Point>> black;
  for (int j = 0; j < squares_y; ++j) {
    for (int i = 0; i < squares_x; ++i) {
      if ((i + j) % 2 != 0) continue;  // the top-left square is black
      black.push_back(view.polygon((i - 1) * s, (j - 1) * s, i * s, j * s));
    }
  }
  for (const auto& square : black) {
    cv::fillPoly(fine, std::vector{square}, cv::Scalar(kBlack * kLevels), cv::LINE_8,
                 kFractionBits);
  }
  cv::Mat coarse;
  cv::resize(fine, coarse, cv::Size(camera.width, camera.height), 0, 0, cv::INTER_AREA);
  cv::Mat reflectance;
  coarse.convertTo(reflectance, CV_32F, 1.0 / kLevels);
  return reflectance;
}

cv::Mat render_tof_intensity(const RigCalibration& rig, const Checkerboard& board,
                             const BoardPose& pose, cv::RNG& rng) {
  cv::Matx33d rotation;
  cv::Rodrigues(pose.rotation, rotation);
  const cv::Mat reflectance =
      render_reflectance(rig.depth, rotation, pose.translation_mm, board, 8);
  cv::Mat noise(reflectance.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 20.0);
  cv::Mat intensity;
  cv::Mat(reflectance * 3000.0 + 200.0 + noise).convertTo(intensity, CV_16U);
  return intensity;
}

cv::Mat render_color_bayer_rg(const RigCalibration& rig, const Checkerboard& board,
                              const BoardPose& pose, cv::RNG& rng) {
  cv::Matx33d board_rotation;
  cv::Rodrigues(pose.rotation, board_rotation);
  const cv::Matx33d rotation = rig.depth_to_color_r * board_rotation;
  const cv::Vec3d translation =
      rig.depth_to_color_r * pose.translation_mm + rig.depth_to_color_t_mm;
  const cv::Mat reflectance = render_reflectance(rig.color, rotation, translation, board, 4);
  cv::Mat noise(reflectance.size(), CV_32F);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, 2.0);
  cv::Mat level = reflectance * 260.0 + 12.0 + noise;
  cv::Mat mosaic(reflectance.size(), CV_8U);
  // R G / G B, with gains of a sensor not white-balanced.
  const double gains[2][2] = {{0.85, 1.0}, {1.0, 0.75}};
  for (int row = 0; row < mosaic.rows; ++row) {
    for (int col = 0; col < mosaic.cols; ++col) {
      mosaic.at<std::uint8_t>(row, col) =
          cv::saturate_cast<std::uint8_t>(level.at<float>(row, col) * gains[row % 2][col % 2]);
    }
  }
  return mosaic;
}

std::vector<cv::Point2d> projected_corners(const RigCalibration& rig, const Checkerboard& board,
                                           const BoardPose& pose, bool in_color) {
  cv::Matx33d rotation;
  cv::Rodrigues(pose.rotation, rotation);
  cv::Vec3d translation = pose.translation_mm;
  if (in_color) {
    rotation = rig.depth_to_color_r * rotation;
    translation = rig.depth_to_color_r * translation + rig.depth_to_color_t_mm;
  }
  std::vector<cv::Point2d> corners;
  for (int row = 0; row < board.inner_corners.height; ++row) {
    for (int col = 0; col < board.inner_corners.width; ++col) {
      corners.push_back(project(in_color ? rig.color : rig.depth, rotation, translation,
                                {col * board.square_mm, row * board.square_mm, 0.0}));
    }
  }
  return corners;
}

}  // namespace tilth::testing
