#include "check_report.h"

#include <cmath>

#include "edge_maps.h"

namespace tilth::calibrate {
namespace {

nlohmann::json distances(const DistanceQuantiles& quantiles) {
  return {{"median_px", quantiles.median_px}, {"p90_px", quantiles.p90_px}};
}

nlohmann::json summary(const AlignmentSummary& s) {
  nlohmann::json entry = {{"depth_edge_pixels", s.depth_edge_pixels},
                          {"color_edge_pixels", s.color_edge_pixels},
                          {"distance_at_zero", distances(s.at_zero)},
                          {"best_shift_px", {s.best_shift.x, s.best_shift.y}},
                          {"distance_at_best_shift", distances(s.at_best)},
                          {"offset_px", {s.offset_px.x, s.offset_px.y}},
                          {"offset_length_px", std::hypot(s.offset_px.x, s.offset_px.y)},
                          {"contrast", s.contrast},
                          {"near_side", to_string(s.near_side)},
                          {"judged", s.cannot_judge.empty()}};
  if (!s.cannot_judge.empty()) entry["cannot_judge"] = s.cannot_judge;
  return entry;
}

}  // namespace

nlohmann::json check_report(const CheckResult& result, const std::string& recording,
                            const std::string& calibration) {
  nlohmann::json frames = nlohmann::json::array();
  for (const FrameAlignment& frame : result.frames) {
    nlohmann::json entry = summary(frame.summary);
    entry["frame_id"] = frame.frame_id;
    frames.push_back(entry);
  }
  return {{"format", "tilth-calibration-check/1"},
          {"recording", recording},
          {"calibration", calibration.empty() ? "the recording's own" : calibration},
          {"verdict", to_string(result.verdict)},
          {"reason", result.reason},
          {"max_offset_px", result.max_offset_px},
          {"overall", summary(result.overall)},
          {"offset_spread_px", result.spread_px},
          {"offset_convention",
           "(dx, dy) in depth pixels from a depth edge to the colour edge that matches it: "
           "the registered colour lies that far right and down of the depth"},
          {"method",
           {{"depth_jump_mm", kDepthJumpMm},
            {"color_canny_thresholds", {kColorEdgeLow, kColorEdgeHigh}},
            {"search_radius_px", kSearchRadiusPx},
            {"truncation_px", kTruncationPx},
            {"quantile_resolution_px", kHistogramBinPx},
            {"min_edge_pixels", kMinEdgePixels},
            {"min_contrast", kMinContrast}}},
          {"frames", frames}};
}

}  // namespace tilth::calibrate
