// `tilth calibrate check`: whether a calibration still registers the colour onto the
// depth, judged from a recording's depth edges and colour edges (docs/calibration.md,
// "Checking a rig in the field").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "edge_alignment.h"
#include "registered_recording.h"

namespace tilth::calibrate {

// A frame is judged on at least this many depth edge pixels and colour edge pixels
// (a few straws' outlines); bare soil has next to none.
constexpr std::uint64_t kMinEdgePixels = 300;
// ... and when its best shift is distinct: its capped mean distance at least this
// fraction below the median over the search window.
constexpr double kMinContrast = 0.2;
// The default for --max-offset-px: the residue mask is dilated by 2 px
// (segmentation's dilation_px), so colour 1.5 px off still masks a straw's mixed depth
// pixels, with half a pixel left for the edges' own placement.
constexpr double kDefaultMaxOffsetPx = 1.5;

enum class Verdict { kHolds, kRecalibrate, kCannotJudge };
const char* to_string(Verdict verdict);

// The numbers of one frame, or of the recording (its judged frames pooled).
struct AlignmentSummary {
  std::uint64_t depth_edge_pixels = 0;
  std::uint64_t color_edge_pixels = 0;
  DistanceQuantiles at_zero;  // depth edge to nearest colour edge, as registered
  cv::Point best_shift;       // the whole-pixel shift of least cost
  DistanceQuantiles at_best;  // ... with the colour edges moved back by it
  cv::Point2d offset_px;      // the registered colour lies this far from the depth
  double contrast = 0.0;
  NearSide near_side = NearSide::kBrighter;  // the polarity that matched better
  std::string cannot_judge;                  // why not; empty when judged
};

struct FrameAlignment {
  std::uint64_t frame_id = 0;
  AlignmentSummary summary;
};

struct CheckResult {
  std::vector<FrameAlignment> frames;
  std::size_t judged_frames = 0;
  // The judged frames pooled; with none judged, only the edge counts, of every frame.
  AlignmentSummary overall;
  // RMS distance of the judged frames' offsets from the overall offset.
  double spread_px = 0.0;
  double max_offset_px = kDefaultMaxOffsetPx;
  Verdict verdict = Verdict::kCannotJudge;
  std::string reason;  // one line: why the verdict
  // The frame with the most depth edges: its registered colour and both edge maps.
  std::uint64_t overlay_frame_id = 0;
  cv::Mat overlay_bgr, overlay_depth_edges, overlay_color_edges;
};

// Replays the recording (throws as replay_registered does) and judges it.
CheckResult check_calibration(const std::filesystem::path& recording, const ReplayOptions& replay,
                              double max_offset_px);

}  // namespace tilth::calibrate
