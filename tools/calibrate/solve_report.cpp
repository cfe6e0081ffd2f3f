#include "solve_report.h"

#include <algorithm>
#include <vector>

namespace tilth::calibrate {
namespace {

// Rows of '#' (a corner fell in the cell) and '.' (none), and the covered fraction.
nlohmann::json coverage(const std::vector<std::vector<cv::Point2f>>& views,
                        const CameraIntrinsics& camera) {
  std::vector<std::string> rows(kCoverageRows, std::string(kCoverageColumns, '.'));
  for (const auto& corners : views) {
    for (const auto& corner : corners) {
      const int col = static_cast<int>((corner.x + 0.5) * kCoverageColumns / camera.width);
      const int row = static_cast<int>((corner.y + 0.5) * kCoverageRows / camera.height);
      if (col >= 0 && col < kCoverageColumns && row >= 0 && row < kCoverageRows) {
        rows[row][col] = '#';
      }
    }
  }
  int covered = 0;
  for (const auto& row : rows) covered += static_cast<int>(std::count(row.begin(), row.end(), '#'));
  return {{"grid", {kCoverageColumns, kCoverageRows}},
          {"cells", rows},
          {"covered_fraction", static_cast<double>(covered) / (kCoverageColumns * kCoverageRows)}};
}

nlohmann::json vec(const cv::Vec3d& value) { return {value[0], value[1], value[2]}; }

}  // namespace

nlohmann::json solve_report(const SolveResult& result, const SolveOptions& options,
                            const std::string& calibration) {
  nlohmann::json views = nlohmann::json::array();
  std::size_t used = 0;
  for (const auto& view : result.views) {
    nlohmann::json entry = {{"name", view.name}, {"used", view.rejected.empty()}};
    if (!view.rejected.empty()) entry["rejected"] = view.rejected;
    if (view.depth_rms_px > 0.0 || view.color_rms_px > 0.0) {
      entry["depth_rms_px"] = view.depth_rms_px;
      entry["color_rms_px"] = view.color_rms_px;
    }
    used += view.rejected.empty();
    views.push_back(entry);
  }
  const ExtrinsicUncertainty& uncertainty = result.uncertainty;
  return {
      {"format", "tilth-calibration-report/1"},
      {"calibration", calibration},
      {"board",
       {{"inner_corners", {options.inner_corners.width, options.inner_corners.height}},
        {"square_mm", options.square_mm}}},
      {"depth_intrinsics", options.calibrate_depth ? "calibrate" : "camera"},
      {"views_used", used},
      {"views_given", result.views.size()},
      {"rms_px",
       {{"depth", result.depth_rms_px},
        {"color", result.color_rms_px},
        {"stereo", result.stereo_rms_px}}},
      {"views", views},
      {"coverage",
       {{"depth", coverage(result.used.depth, result.rig.depth)},
        {"color", coverage(result.used.color, result.rig.color)}}},
      {"uncertainty",
       {{"method",
         "Gauss-Newton covariance sigma^2 (J^T J)^-1 of the stereo reprojection over R, T, "
         "the solved intrinsics (both cameras', or the colour camera's when the ToF "
         "camera's were given) and every view's board pose; J by central differences of "
         "cv::projectPoints, sigma from the residuals; the standard deviations are its "
         "marginals"},
        {"rotation_std_deg", vec(uncertainty.rotation_std_deg)},
        {"rotation_axes", "small rotations about the colour camera's x, y, z axes"},
        {"translation_std_mm", vec(uncertainty.translation_std_mm)},
        {"residual_std_px", uncertainty.residual_std_px}}},
  };
}

}  // namespace tilth::calibrate
