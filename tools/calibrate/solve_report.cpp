#include "solve_report.h"

#include <vector>

#include "board_coverage.h"

namespace tilth::calibrate {
namespace {

nlohmann::json coverage(const std::vector<std::vector<cv::Point2f>>& views,
                        const CameraIntrinsics& camera) {
  BoardCoverage grid({camera.width, camera.height});
  for (const auto& corners : views) grid.add(corners);
  return {{"grid", {BoardCoverage::kColumns, BoardCoverage::kRows}},
          {"cells", grid.cells()},
          {"covered_fraction", grid.covered_fraction()}};
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
