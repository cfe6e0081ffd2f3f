// Images of a checkerboard as a rig's two cameras see it, with known corner positions:
// the inputs of the calibration tests. Edges are anti-aliased by supersampling, and the
// lens distortion is the project's own model (camera_geometry/lens_model.h).
#pragma once

#include <opencv2/core.hpp>

#include "tilth/calibration.h"

namespace tilth::testing {

struct Checkerboard {
  cv::Size inner_corners{8, 5};  // columns x rows: 9 x 6 squares
  double square_mm = 40.0;
  double margin_mm = 30.0;  // white paper around the squares
};

// Where the board is in the ToF camera: P_depth = R(rotation) * P_board + translation_mm.
// The board's origin is its first inner corner, x along its rows, y down its columns,
// so inner corner (col, row) is at (col, row, 0) * square_mm, as `tilth calibrate` counts.
struct BoardPose {
  cv::Vec3d rotation;  // Rodrigues vector
  cv::Vec3d translation_mm;
};

// The board's reflectance (0.05 black, 0.85 white, 0.35 beyond the paper) on `camera`'s
// pixel grid, CV_32F: each pixel the mean of `supersampling`^2 samples. `rotation` and
// `translation_mm` take board points into this camera's frame.
cv::Mat render_reflectance(const CameraIntrinsics& camera, const cv::Matx33d& rotation,
                           const cv::Vec3d& translation_mm, const Checkerboard& board,
                           int supersampling);

// The ToF intensity (CV_16U, about 200 to 2750 counts, Gaussian noise of 20 counts).
cv::Mat render_tof_intensity(const RigCalibration& rig, const Checkerboard& board,
                             const BoardPose& pose, cv::RNG& rng);

// The colour camera's raw Bayer RG8 mosaic (CV_8U, R G / G B; the channels' gains differ
// as an unbalanced sensor's do; Gaussian noise of 2 levels).
cv::Mat render_color_bayer_rg(const RigCalibration& rig, const Checkerboard& board,
                              const BoardPose& pose, cv::RNG& rng);

// The pixel positions of the inner corners in the ToF (`in_color` false) or colour image.
std::vector<cv::Point2d> projected_corners(const RigCalibration& rig, const Checkerboard& board,
                                           const BoardPose& pose, bool in_color);

}  // namespace tilth::testing
