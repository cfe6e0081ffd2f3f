#include "calibration_check.h"

#include <array>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "edge_maps.h"
#include "tilth/error.h"

namespace tilth::calibrate {
namespace {

AlignmentSummary summarise(const ShiftedDistances& distances, NearSide side) {
  AlignmentSummary summary;
  summary.near_side = side;
  summary.depth_edge_pixels = distances.depth_edge_pixels();
  summary.color_edge_pixels = distances.color_edge_pixels();
  summary.at_zero = distances.quantiles({0, 0});
  summary.best_shift = distances.best_shift();
  summary.at_best = distances.quantiles(summary.best_shift);
  summary.offset_px = distances.best_offset();
  summary.contrast = distances.contrast();
  std::ostringstream why;
  if (summary.depth_edge_pixels < kMinEdgePixels || summary.color_edge_pixels < kMinEdgePixels) {
    why << summary.depth_edge_pixels << " depth edge pixels and " << summary.color_edge_pixels
        << " colour edge pixels, " << kMinEdgePixels
        << " of each needed: too few edges to go by (bare soil? the colour dark, overexposed "
           "or out of focus?)";
  } else if (summary.contrast < kMinContrast) {
    why << std::fixed << std::setprecision(2)
        << "no shift matches the edges distinctly better than the others (contrast "
        << summary.contrast << ", " << kMinContrast << " needed); a rig knocked further than the "
        << kSearchRadiusPx << " px searched looks like this too: see the overlay";
  }
  summary.cannot_judge = why.str();
  return summary;
}

// The polarity whose best shift matches better.
NearSide better_side(const std::array<ShiftedDistances, 2>& sides) {
  const auto best_cost = [](const ShiftedDistances& d) { return d.cost(d.best_shift()); };
  return best_cost(sides[1]) < best_cost(sides[0]) ? NearSide::kDarker : NearSide::kBrighter;
}

}  // namespace

const char* to_string(Verdict verdict) {
  switch (verdict) {
    case Verdict::kHolds:
      return "holds";
    case Verdict::kRecalibrate:
      return "recalibrate";
    case Verdict::kCannotJudge:
      return "cannot judge";
  }
  return "?";
}

CheckResult check_calibration(const std::filesystem::path& recording, const ReplayOptions& replay,
                              double max_offset_px) {
  CheckResult result;
  result.max_offset_px = max_offset_px;
  std::array<ShiftedDistances, 2> pooled;  // by NearSide
  std::uint64_t most_edges = 0;
  replay_registered(recording, replay, [&](const RegisteredFrame& frame) {
    const cv::Mat region = color_region(frame.status);
    cv::Mat depth = depth_edges(frame.depth_mm);
    depth.setTo(0, region == 0);  // no colour there to find an edge in
    const cv::Mat color = color_edges(frame.bgr, region);
    const DirectedDistances to_color(color);
    std::array<ShiftedDistances, 2> sides;
    for (const NearSide side : {NearSide::kBrighter, NearSide::kDarker}) {
      sides[static_cast<int>(side)].add_frame(depth, to_color, side);
    }
    const NearSide side = better_side(sides);
    const AlignmentSummary summary = summarise(sides[static_cast<int>(side)], side);
    if (summary.cannot_judge.empty()) {
      for (int i = 0; i < 2; ++i) pooled[i].add(sides[i]);
    }
    if (result.overlay_bgr.empty() || summary.depth_edge_pixels > most_edges) {
      most_edges = summary.depth_edge_pixels;
      result.overlay_frame_id = frame.frame_id;
      result.overlay_bgr = frame.bgr.clone();
      result.overlay_depth_edges = depth;
      result.overlay_color_edges = color;
    }
    result.frames.push_back({frame.frame_id, summary});
  });
  if (result.frames.empty()) {
    throw Error(recording.string() +
                ": holds no frames (expected at least one depth and colour pair)");
  }

  for (const FrameAlignment& frame : result.frames) {
    result.judged_frames += frame.summary.cannot_judge.empty();
  }
  const std::size_t judged = result.judged_frames;
  if (judged == 0) {
    // The edges of every frame, and the first frame's reason.
    for (const FrameAlignment& frame : result.frames) {
      result.overall.depth_edge_pixels += frame.summary.depth_edge_pixels;
      result.overall.color_edge_pixels += frame.summary.color_edge_pixels;
    }
    result.overall.cannot_judge = result.frames.front().summary.cannot_judge;
    result.verdict = Verdict::kCannotJudge;
    result.reason = "no frame could be judged; the first: " + result.overall.cannot_judge;
    return result;
  }
  const NearSide side = better_side(pooled);
  result.overall = summarise(pooled[static_cast<int>(side)], side);
  if (!result.overall.cannot_judge.empty()) {
    result.verdict = Verdict::kCannotJudge;
    result.reason = "the frames together: " + result.overall.cannot_judge;
    return result;
  }
  double squares = 0.0;
  for (const FrameAlignment& frame : result.frames) {
    if (!frame.summary.cannot_judge.empty()) continue;
    const cv::Point2d d = frame.summary.offset_px - result.overall.offset_px;
    squares += d.dot(d);
  }
  result.spread_px = std::sqrt(squares / static_cast<double>(judged));
  const double offset = std::hypot(result.overall.offset_px.x, result.overall.offset_px.y);
  std::ostringstream reason;
  reason << std::fixed << std::setprecision(2) << "the colour lies " << offset
         << " px from the depth (" << judged << " of " << result.frames.size()
         << " frames judged); at most " << max_offset_px << " px holds";
  result.reason = reason.str();
  result.verdict = offset > max_offset_px ? Verdict::kRecalibrate : Verdict::kHolds;
  return result;
}

}  // namespace tilth::calibrate
