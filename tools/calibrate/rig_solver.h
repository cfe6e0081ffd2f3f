// Zhang's method for a ToF + colour rig: each camera's intrinsics from the board's
// corners (the ToF camera's optionally given), then the transform between them with the
// intrinsics fixed, then (both calibrated) all refined together; views that fit badly are
// rejected, with the reason, and it solves again.
#pragma once

#include <cstddef>
#include <ostream>
#include <string>
#include <vector>

#include "board_views.h"
#include "extrinsic_uncertainty.h"
#include "tilth/calibration.h"

namespace tilth::calibrate {

struct SolveOptions {
  cv::Size inner_corners;  // columns x rows, OpenCV's patternSize
  double square_mm = 0.0;
  bool calibrate_depth = true;  // else the rig's ToF intrinsics are kept (the camera's own)
};

// Fewer views than this leave the lens distortion poorly determined.
constexpr std::size_t kMinViews = 6;
// A view is rejected when its RMS in either camera exceeds this many times the median
// view's and kRejectFloorPx (a board that moved between the two exposures, a blurred or
// misdetected image): the worst such view, then the solve is repeated without it.
constexpr double kRejectFactor = 3.0;
constexpr double kRejectFloorPx = 0.5;

struct ViewResult {
  std::string name;
  std::string rejected;       // why the view is not used; empty when it is
  double depth_rms_px = 0.0;  // of the last solve the view took part in
  double color_rms_px = 0.0;
};

struct SolveResult {
  RigCalibration rig;
  // Reprojection errors of the solution over the used views: in each camera, and both.
  double depth_rms_px = 0.0;
  double color_rms_px = 0.0;
  double stereo_rms_px = 0.0;
  std::vector<ViewResult> views;
  StereoCorners used;  // the corners of the views used
  ExtrinsicUncertainty uncertainty;
};

// `rig` gives what the views do not (depth scale, models; the ToF intrinsics unless
// options.calibrate_depth). Prints each rejected view and why to `log`. Throws
// tilth::Error when no view shows the board in both images, when fewer than kMinViews
// remain, or when the views' image sizes differ from each other or from `rig`'s.
SolveResult solve_rig(const std::vector<BoardView>& views, const RigCalibration& rig,
                      const SolveOptions& options, std::ostream& log);

}  // namespace tilth::calibrate
