// How well a set of board views determines the rotation and translation between the two
// cameras: standard deviations from the Jacobian of the stereo reprojection.
#pragma once

#include <vector>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "tilth/calibration.h"

namespace tilth::calibrate {

// The corners of the views both cameras saw, in the same order.
struct StereoCorners {
  std::vector<std::vector<cv::Point3f>> board;  // mm, on the board (z = 0)
  std::vector<std::vector<cv::Point2f>> depth;
  std::vector<std::vector<cv::Point2f>> color;
};

struct ExtrinsicUncertainty {
  cv::Vec3d rotation_std_deg;  // small rotations about the colour camera's x, y, z axes
  cv::Vec3d translation_std_mm;
  double residual_std_px = 0.0;  // per image coordinate, from the residuals
};

// The Gauss-Newton covariance sigma^2 (J^T J)^-1 of the rotation, the translation, the
// colour camera's intrinsics, the ToF camera's when `depth_intrinsics_solved` (else they
// are known), and every view's board pose, at the rig's values and each view's board
// pose refined against both images; the standard deviations of R and T are its
// marginals, so what the intrinsics leave open is in them. J by central differences of
// cv::projectPoints; sigma from the residuals.
ExtrinsicUncertainty extrinsic_uncertainty(const StereoCorners& corners, const RigCalibration& rig,
                                           bool depth_intrinsics_solved);

}  // namespace tilth::calibrate
