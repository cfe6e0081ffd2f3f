#include "rig_solver.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/calib3d.hpp>

#include "tilth/error.h"

namespace tilth::calibrate {
namespace {

std::string size_text(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Every view's images are the size of the first view's: another size is another camera
// (or another binning), whose corners would be solved as if they were this one's.
void check_sizes(const std::vector<BoardView>& views, const RigCalibration& rig, bool given_sizes) {
  const BoardView& first = views.front();
  for (const auto& view : views) {
    if (view.depth_size != first.depth_size) {
      throw Error(view.name + ": the intensity image is " + size_text(view.depth_size) + ", " +
                  first.name + "'s " + size_text(first.depth_size) +
                  "; expected every view's from the same ToF camera");
    }
    if (view.color_size != first.color_size) {
      throw Error(view.name + ": the colour image is " + size_text(view.color_size) + ", " +
                  first.name + "'s " + size_text(first.color_size) +
                  "; expected every view's from the same colour camera");
    }
  }
  if (!given_sizes) return;
  const cv::Size depth(rig.depth.width, rig.depth.height);
  const cv::Size color(rig.color.width, rig.color.height);
  if (first.depth_size != depth || first.color_size != color) {
    throw Error(
        "the views' images are " + size_text(first.depth_size) + " (intensity) and " +
        size_text(first.color_size) + " (colour), " +
        (rig.origin.empty() ? "--depth-size and --color-size say" : rig.origin + "'s cameras") +
        " " + size_text(depth) + " and " + size_text(color) +
        "; expected images of the calibration's cameras");
  }
}

std::vector<cv::Point3f> board_points(const SolveOptions& options) {
  std::vector<cv::Point3f> points;
  for (int row = 0; row < options.inner_corners.height; ++row) {
    for (int col = 0; col < options.inner_corners.width; ++col) {
      points.emplace_back(static_cast<float>(col * options.square_mm),
                          static_cast<float>(row * options.square_mm), 0.0f);
    }
  }
  return points;
}

void set_intrinsics(CameraIntrinsics& camera, cv::Size size, const cv::Mat& matrix,
                    const cv::Mat& distortion) {
  camera.width = size.width;
  camera.height = size.height;
  camera.fx = matrix.at<double>(0, 0);
  camera.fy = matrix.at<double>(1, 1);
  camera.cx = matrix.at<double>(0, 2);
  camera.cy = matrix.at<double>(1, 2);
  for (int i = 0; i < 5; ++i) camera.distortion[i] = distortion.at<double>(i);
}

// The RMS over views of equal corner counts, from each view's RMS.
double rms_of(const std::vector<double>& per_view) {
  double sum = 0.0;
  for (const double rms : per_view) sum += rms * rms;
  return std::sqrt(sum / per_view.size());
}

// One camera's intrinsics and distortion (k1, k2, p1, p2, k3) from the corners alone.
void calibrate_camera(const std::vector<std::vector<cv::Point3f>>& board,
                      const std::vector<std::vector<cv::Point2f>>& corners, cv::Size size,
                      CameraIntrinsics& camera) {
  cv::Mat matrix;
  cv::Mat distortion;
  cv::calibrateCamera(board, corners, size, matrix, distortion, cv::noArray(), cv::noArray());
  set_intrinsics(camera, size, matrix, distortion);
}

// One solve on the given views' corners: the rig, and each view's RMS in each camera
// (rows: views; columns: ToF, colour).
struct Solution {
  RigCalibration rig;
  cv::Mat view_errors;
  double stereo_rms_px = 0.0;
};

Solution solve_once(const StereoCorners& corners, RigCalibration rig, cv::Size depth_size,
                    cv::Size color_size, bool calibrate_depth) {
  if (calibrate_depth) calibrate_camera(corners.board, corners.depth, depth_size, rig.depth);
  calibrate_camera(corners.board, corners.color, color_size, rig.color);
  rig.depth.width = depth_size.width;
  rig.depth.height = depth_size.height;

  // The transform with both cameras' intrinsics fixed; then, when both were calibrated
  // here, everything refined together: the colour camera's sharper corners pin the
  // board poses that the ToF camera's focal length and principal point depend on (on
  // rendered views this halves their error, and T's with them).
  cv::Mat depth_matrix(rig.depth.camera_matrix());
  cv::Mat color_matrix(rig.color.camera_matrix());
  cv::Mat depth_distortion(cv::Matx<double, 1, 5>(rig.depth.distortion.data()));
  cv::Mat color_distortion(cv::Matx<double, 1, 5>(rig.color.distortion.data()));
  cv::Mat rotation;
  cv::Mat translation;
  Solution solution;
  solution.stereo_rms_px = cv::stereoCalibrate(
      corners.board, corners.depth, corners.color, depth_matrix, depth_distortion, color_matrix,
      color_distortion, depth_size, rotation, translation, cv::noArray(), cv::noArray(),
      solution.view_errors, cv::CALIB_FIX_INTRINSIC);
  if (calibrate_depth) {
    solution.stereo_rms_px = cv::stereoCalibrate(
        corners.board, corners.depth, corners.color, depth_matrix, depth_distortion, color_matrix,
        color_distortion, depth_size, rotation, translation, cv::noArray(), cv::noArray(),
        solution.view_errors, cv::CALIB_USE_INTRINSIC_GUESS | cv::CALIB_USE_EXTRINSIC_GUESS);
    set_intrinsics(rig.depth, depth_size, depth_matrix, depth_distortion);
    set_intrinsics(rig.color, color_size, color_matrix, color_distortion);
  }
  rig.depth_to_color_r = cv::Matx33d(rotation.ptr<double>());
  rig.depth_to_color_t_mm = cv::Vec3d(translation.ptr<double>());
  solution.rig = rig;
  return solution;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

std::string not_found_reason(const BoardView& view) {
  if (view.depth_corners.empty() && view.color_corners.empty())
    return "board not found in either image";
  if (view.depth_corners.empty()) return "board not found in the intensity image";
  return "board not found in the colour image";
}

}  // namespace

SolveResult solve_rig(const std::vector<BoardView>& views, const RigCalibration& rig,
                      const SolveOptions& options, std::ostream& log) {
  if (views.empty()) throw Error("no views given");
  const bool given_sizes = rig.depth.width > 0 && rig.color.width > 0;
  check_sizes(views, rig, given_sizes);
  const std::string board = std::to_string(options.inner_corners.width) + "x" +
                            std::to_string(options.inner_corners.height);

  SolveResult result;
  std::vector<std::size_t> used;  // into views and result.views
  std::size_t found_depth = 0;
  std::size_t found_color = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    result.views.push_back({views[v].name, "", 0.0, 0.0});
    found_depth += !views[v].depth_corners.empty();
    found_color += !views[v].color_corners.empty();
    if (views[v].depth_corners.empty() || views[v].color_corners.empty()) {
      result.views[v].rejected = not_found_reason(views[v]);
      log << views[v].name << ": skipped: " << result.views[v].rejected << "\n";
    } else {
      used.push_back(v);
    }
  }
  if (used.empty()) {
    throw Error("no view shows a board of " + board + " inner corners in both images (of " +
                std::to_string(views.size()) + " views, found in " + std::to_string(found_depth) +
                " intensity and " + std::to_string(found_color) +
                " colour images); expected --board to count the inner corners along and "
                "across, e.g. 8x5 for a board of 9x6 squares");
  }
  const cv::Size depth_size = views.front().depth_size;
  const cv::Size color_size = views.front().color_size;
  const std::vector<cv::Point3f> points = board_points(options);

  while (true) {
    if (used.size() < kMinViews) {
      throw Error("only " + std::to_string(used.size()) + " of " + std::to_string(views.size()) +
                  " views usable (the others are listed above with why); expected at least " +
                  std::to_string(kMinViews) + ", better 15 to 20 spread over both images");
    }
    StereoCorners corners;
    for (const std::size_t v : used) {
      corners.board.push_back(points);
      corners.depth.push_back(views[v].depth_corners);
      corners.color.push_back(views[v].color_corners);
    }
    const Solution solution =
        solve_once(corners, rig, depth_size, color_size, options.calibrate_depth);
    std::vector<double> worst(used.size());
    std::vector<double> depth_errors(used.size());
    std::vector<double> color_errors(used.size());
    for (std::size_t i = 0; i < used.size(); ++i) {
      ViewResult& view = result.views[used[i]];
      view.depth_rms_px = depth_errors[i] = solution.view_errors.at<double>(static_cast<int>(i), 0);
      view.color_rms_px = color_errors[i] = solution.view_errors.at<double>(static_cast<int>(i), 1);
      worst[i] = std::max(view.depth_rms_px, view.color_rms_px);
    }
    // The worst view alone, then solve again: one bad view inflates the others' errors
    // (and the median) until it is gone.
    const double limit = std::max(kRejectFactor * median(worst), kRejectFloorPx);
    const auto worst_view = std::max_element(worst.begin(), worst.end()) - worst.begin();
    if (worst[worst_view] <= limit) {
      result.rig = solution.rig;
      result.depth_rms_px = rms_of(depth_errors);
      result.color_rms_px = rms_of(color_errors);
      result.stereo_rms_px = solution.stereo_rms_px;
      result.used = std::move(corners);
      break;
    }
    ViewResult& view = result.views[used[worst_view]];
    char reason[160];
    std::snprintf(reason, sizeof reason,
                  "RMS %.3f px (intensity), %.3f px (colour), above %.3f px (%.0f times the "
                  "median view's, at least %.1f px)",
                  view.depth_rms_px, view.color_rms_px, limit, kRejectFactor, kRejectFloorPx);
    view.rejected = reason;
    log << view.name << ": rejected: " << reason << "\n";
    used.erase(used.begin() + worst_view);
  }
  result.uncertainty = extrinsic_uncertainty(result.used, result.rig, options.calibrate_depth);
  return result;
}

}  // namespace tilth::calibrate
