// Where each depth pixel is seen in the colour image: the full projective mapping of
// docs/formats/calibration.md with both cameras' lens distortion. The undistorted coordinates of
// the depth pixels are computed once per calibration; a frame costs a few multiply-adds
// and one division per pixel, in the widest vectors the CPU has (row_kernels.h).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "row_kernels.h"
#include "tilth/calibration.h"

namespace tilth::registration {

class DepthToColor {
 public:
  static constexpr float kEdgeMarginPx = 1e-3f;

  // `file` names the calibration in errors; `kernels`: the instruction-set level.
  DepthToColor(const RigCalibration& rig, const std::string& file, const RowKernels& kernels);

  // For the depth pixels of row `row` at z_mm (mm from the mounting surface, NaN = no
  // depth): the colour pixel (color_u, color_v; 0-based, (0,0) at the centre of the
  // top-left pixel) and the depth along the colour camera's axis. color_depth is NaN
  // where the colour image does not show the point: no depth, behind the colour camera,
  // outside [-0.5, width - 0.5) x [-0.5, height - 0.5), or beyond the radius where the
  // distortion polynomial turns back and would fold far-off points into the image.
  // Points within kEdgeMarginPx of the right and bottom edges count as outside, so that
  // rounding u + 0.5 in float never reaches the width. Each output holds row_capacity()
  // floats.
  void project_row(int row, const float* z_mm, float* color_u, float* color_v,
                   float* color_depth) const;

  int row_capacity() const { return model_.row_capacity; }  // depth width in whole vectors
  int depth_width() const { return model_.depth_width; }
  int depth_height() const { return depth_height_; }
  int color_width() const { return model_.color_width; }
  int color_height() const { return model_.color_height; }
  const RowKernels& kernels() const { return kernels_; }

 private:
  ProjectionModel model_;
  int depth_height_;
  const RowKernels& kernels_;
  // Undistorted normalised coordinates of the depth pixels. Without depth distortion x'
  // depends on u only and y' on v only (one row of x', one y' per row), which keeps
  // megabytes of tables out of the per-frame memory traffic; otherwise both are tables
  // of depth_height rows of row_capacity.
  bool separable_;
  std::vector<float> x_;
  std::vector<float> y_;
};

}  // namespace tilth::registration
