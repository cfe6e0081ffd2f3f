#include "extrinsic_uncertainty.h"

#include <cmath>

#include <opencv2/calib3d.hpp>

namespace tilth::calibrate {
namespace {

constexpr int kPose = 6;        // rotation vector, translation
constexpr int kIntrinsics = 9;  // fx, fy, cx, cy, k1, k2, p1, p2, k3

cv::Matx33d rotation_of(const cv::Vec3d& vector) {
  cv::Matx33d rotation;
  cv::Rodrigues(vector, rotation);
  return rotation;
}

cv::Vec3d vector_of(const cv::Matx33d& rotation) {
  cv::Vec3d vector;
  cv::Rodrigues(rotation, vector);
  return vector;
}

// A camera's intrinsics moved by `delta` (kIntrinsics values from `at`).
struct Lens {
  cv::Matx33d matrix;
  cv::Matx<double, 1, 5> distortion;

  Lens(const CameraIntrinsics& camera, const double* delta)
      : matrix(camera.camera_matrix()), distortion(camera.distortion.data()) {
    if (delta == nullptr) return;
    matrix(0, 0) += delta[0];
    matrix(1, 1) += delta[1];
    matrix(0, 2) += delta[2];
    matrix(1, 2) += delta[3];
    for (int i = 0; i < 5; ++i) distortion(i) += delta[4 + i];
  }
};

// The stereo problem: residuals (projected minus found, in pixels) of a view in both
// cameras, given a change of the rig's parameters (`rig_delta`: the colour camera turned
// by Rodrigues(rig_delta[0..2]) * R, so its parts are angles about the colour camera's
// axes; moved by rig_delta[3..5] mm; then the colour camera's intrinsics, then the ToF
// camera's when they were solved for) and the board's pose in the ToF camera.
class StereoResiduals {
 public:
  StereoResiduals(const StereoCorners& corners, const RigCalibration& rig, bool depth_solved)
      : corners_(corners),
        rig_(rig),
        rig_parameters_(kPose + kIntrinsics * (depth_solved ? 2 : 1)) {}

  std::size_t views() const { return corners_.board.size(); }
  int rows(std::size_t view) const { return static_cast<int>(corners_.board[view].size()) * 4; }
  int rig_parameters() const { return rig_parameters_; }

  cv::Mat residuals(std::size_t view, const std::vector<double>& board,
                    const std::vector<double>& rig_delta) const {
    const std::vector<cv::Point3d> points(corners_.board[view].begin(), corners_.board[view].end());
    const Lens color_lens(rig_.color, &rig_delta[kPose]);
    const Lens depth_lens(rig_.depth, rig_parameters_ > kPose + kIntrinsics
                                          ? &rig_delta[kPose + kIntrinsics]
                                          : nullptr);
    const cv::Vec3d board_rotation(board[0], board[1], board[2]);
    const cv::Vec3d board_translation(board[3], board[4], board[5]);
    std::vector<cv::Point2d> depth;
    cv::projectPoints(points, board_rotation, board_translation, depth_lens.matrix,
                      depth_lens.distortion, depth);
    const cv::Matx33d rotation =
        rotation_of({rig_delta[0], rig_delta[1], rig_delta[2]}) * rig_.depth_to_color_r;
    const cv::Vec3d translation = rotation * board_translation + rig_.depth_to_color_t_mm +
                                  cv::Vec3d(rig_delta[3], rig_delta[4], rig_delta[5]);
    std::vector<cv::Point2d> color;
    cv::projectPoints(points, vector_of(rotation * rotation_of(board_rotation)), translation,
                      color_lens.matrix, color_lens.distortion, color);
    cv::Mat result(rows(view), 1, CV_64F);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const int row = static_cast<int>(i) * 4;
      result.at<double>(row) = depth[i].x - corners_.depth[view][i].x;
      result.at<double>(row + 1) = depth[i].y - corners_.depth[view][i].y;
      result.at<double>(row + 2) = color[i].x - corners_.color[view][i].x;
      result.at<double>(row + 3) = color[i].y - corners_.color[view][i].y;
    }
    return result;
  }

  // d residuals / d (the board's pose, or the rig's parameters) by central differences:
  // steps of 1e-6 (rad, distortion coefficients) and 1e-4 (mm, px), far above rounding
  // and far below the curvature.
  cv::Mat jacobian(std::size_t view, const std::vector<double>& board, bool of_board) const {
    const std::vector<double> rig_zero(rig_parameters_, 0.0);
    const int columns = of_board ? kPose : rig_parameters_;
    cv::Mat result(rows(view), columns, CV_64F);
    for (int p = 0; p < columns; ++p) {
      const bool angular =
          of_board ? p < 3 : (p < 3 || (p >= kPose && (p - kPose) % kIntrinsics >= 4));
      const double step = angular ? 1e-6 : 1e-4;
      auto plus_board = board;
      auto minus_board = board;
      auto plus_rig = rig_zero;
      auto minus_rig = rig_zero;
      (of_board ? plus_board : plus_rig)[p] += step;
      (of_board ? minus_board : minus_rig)[p] -= step;
      const cv::Mat column =
          (residuals(view, plus_board, plus_rig) - residuals(view, minus_board, minus_rig)) /
          (2.0 * step);
      column.copyTo(result.col(p));
    }
    return result;
  }

  // The board's pose in the ToF camera: from the ToF corners alone, then refined against
  // both images with the rig held (Gauss-Newton; a few steps from a PnP start).
  std::vector<double> board_pose(std::size_t view) const {
    cv::Vec3d rotation;
    cv::Vec3d translation;
    cv::solvePnP(corners_.board[view], corners_.depth[view], rig_.depth.camera_matrix(),
                 cv::Matx<double, 1, 5>(rig_.depth.distortion.data()), rotation, translation);
    std::vector<double> pose = {rotation[0],    rotation[1],    rotation[2],
                                translation[0], translation[1], translation[2]};
    const std::vector<double> rig_zero(rig_parameters_, 0.0);
    for (int iteration = 0; iteration < 10; ++iteration) {
      const cv::Mat j = jacobian(view, pose, true);
      const cv::Mat r = residuals(view, pose, rig_zero);
      cv::Mat step;
      cv::solve(j.t() * j, -j.t() * r, step, cv::DECOMP_CHOLESKY);
      for (int p = 0; p < kPose; ++p) pose[p] += step.at<double>(p);
      if (cv::norm(step) < 1e-10) break;
    }
    return pose;
  }

 private:
  const StereoCorners& corners_;
  const RigCalibration& rig_;
  int rig_parameters_;
};

}  // namespace

ExtrinsicUncertainty extrinsic_uncertainty(const StereoCorners& corners, const RigCalibration& rig,
                                           bool depth_intrinsics_solved) {
  const StereoResiduals problem(corners, rig, depth_intrinsics_solved);
  int total_rows = 0;
  for (std::size_t v = 0; v < problem.views(); ++v) total_rows += problem.rows(v);
  const int global = problem.rig_parameters();
  const int parameters = global + kPose * static_cast<int>(problem.views());
  cv::Mat j = cv::Mat::zeros(total_rows, parameters, CV_64F);
  double squared_sum = 0.0;
  int row = 0;
  for (std::size_t v = 0; v < problem.views(); ++v) {
    const std::vector<double> board = problem.board_pose(v);
    const int rows = problem.rows(v);
    problem.jacobian(v, board, false).copyTo(j(cv::Rect(0, row, global, rows)));
    problem.jacobian(v, board, true)
        .copyTo(j(cv::Rect(global + kPose * static_cast<int>(v), row, kPose, rows)));
    squared_sum +=
        cv::norm(problem.residuals(v, board, std::vector<double>(global, 0.0)), cv::NORM_L2SQR);
    row += rows;
  }
  ExtrinsicUncertainty result;
  result.residual_std_px = std::sqrt(squared_sum / std::max(1, total_rows - parameters));
  cv::Mat covariance;
  cv::invert(j.t() * j, covariance, cv::DECOMP_SVD);
  covariance *= result.residual_std_px * result.residual_std_px;
  for (int i = 0; i < 3; ++i) {
    result.rotation_std_deg[i] = std::sqrt(covariance.at<double>(i, i)) * 180.0 / CV_PI;
    result.translation_std_mm[i] = std::sqrt(covariance.at<double>(i + 3, i + 3));
  }
  return result;
}

}  // namespace tilth::calibrate
