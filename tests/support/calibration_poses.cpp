#include "calibration_poses.h"

#include <array>
#include <cmath>

#include <opencv2/calib3d.hpp>

#include "camera_geometry/lens_model.h"

namespace tilth::testing {
namespace {

// Where the board's centre is aimed, as fractions of the ToF image: corners, edges, middle.
const std::array<cv::Point2d, 9> kTargets = {{{0.12, 0.12},
                                              {0.88, 0.12},
                                              {0.12, 0.88},
                                              {0.88, 0.88},
                                              {0.5, 0.5},
                                              {0.5, 0.12},
                                              {0.5, 0.88},
                                              {0.12, 0.5},
                                              {0.88, 0.5}}};

bool inside(const CameraIntrinsics& camera, const cv::Matx33d& rotation,
            const cv::Vec3d& translation, const cv::Vec3d& point, double border_px) {
  const cv::Vec3d p = rotation * point + translation;
  if (p[2] <= 0.0) return false;
  double x = p[0] / p[2];
  double y = p[1] / p[2];
  lens::distortion_of(camera).apply(x, y);
  const double u = camera.fx * x + camera.cx;
  const double v = camera.fy * y + camera.cy;
  return u >= border_px - 0.5 && v >= border_px - 0.5 && u <= camera.width - 0.5 - border_px &&
         v <= camera.height - 0.5 - border_px;
}

double radians(double degrees) { return degrees * CV_PI / 180.0; }

}  // namespace

bool board_inside_both(const RigCalibration& rig, const Checkerboard& board, const BoardPose& pose,
                       double border_px) {
  cv::Matx33d rotation;
  cv::Rodrigues(pose.rotation, rotation);
  const cv::Matx33d color_rotation = rig.depth_to_color_r * rotation;
  const cv::Vec3d color_translation =
      rig.depth_to_color_r * pose.translation_mm + rig.depth_to_color_t_mm;
  const double s = board.square_mm;
  const double m = board.margin_mm;
  const double x1 = board.inner_corners.width * s + m;
  const double y1 = board.inner_corners.height * s + m;
  // The paper's outline, densely: a distorted edge bulges between its corners.
  for (int i = 0; i <= 20; ++i) {
    const double f = i / 20.0;
    const double x = -s - m + f * (x1 + s + m);
    const double y = -s - m + f * (y1 + s + m);
    for (const cv::Vec3d& point : {cv::Vec3d(x, -s - m, 0), cv::Vec3d(x, y1, 0),
                                   cv::Vec3d(-s - m, y, 0), cv::Vec3d(x1, y, 0)}) {
      if (!inside(rig.depth, rotation, pose.translation_mm, point, border_px) ||
          !inside(rig.color, color_rotation, color_translation, point, border_px)) {
        return false;
      }
    }
  }
  return true;
}

std::vector<BoardPose> calibration_poses(const RigCalibration& rig, const Checkerboard& board,
                                         int count, std::uint64_t seed) {
  cv::RNG rng(seed);
  const cv::Vec3d centre((board.inner_corners.width - 1) * board.square_mm / 2.0,
                         (board.inner_corners.height - 1) * board.square_mm / 2.0, 0.0);
  std::vector<BoardPose> poses;
  for (int n = 0; poses.size() < static_cast<std::size_t>(count) && n < 50 * count; ++n) {
    const cv::Point2d target = kTargets[n % kTargets.size()];
    const double sign_x = rng.uniform(0, 2) ? 1.0 : -1.0;
    const double sign_y = rng.uniform(0, 2) ? 1.0 : -1.0;
    const cv::Vec3d tilt(sign_x * radians(rng.uniform(15.0, 40.0)),
                         sign_y * radians(rng.uniform(15.0, 40.0)),
                         radians(rng.uniform(-12.0, 12.0)));
    cv::Matx33d rotation;
    cv::Rodrigues(tilt, rotation);
    double distance = rng.uniform(550.0, 1000.0);
    // From the aimed point toward the middle, then farther, until the board fits.
    for (int attempt = 0; attempt < 60; ++attempt) {
      const double pull = std::min(1.0, (attempt % 10) / 10.0);
      const cv::Point2d aim = target + (cv::Point2d(0.5, 0.5) - target) * pull;
      const double u = aim.x * rig.depth.width - 0.5;
      const double v = aim.y * rig.depth.height - 0.5;
      const cv::Vec3d ray((u - rig.depth.cx) / rig.depth.fx, (v - rig.depth.cy) / rig.depth.fy,
                          1.0);
      const BoardPose pose{tilt, ray * distance - rotation * centre};
      if (board_inside_both(rig, board, pose, 4.0)) {
        poses.push_back(pose);
        break;
      }
      if (attempt % 10 == 9) distance += 100.0;
    }
  }
  return poses;
}

}  // namespace tilth::testing
