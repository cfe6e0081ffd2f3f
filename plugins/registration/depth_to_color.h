// Where each depth pixel is seen in the colour image: the full projective mapping of
// spec/calibration.md with both cameras' lens distortion. The undistorted coordinates of
// the depth pixels are computed once per calibration; a frame costs a few multiply-adds
// and one division per pixel, four pixels at a time.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "tilth/calibration.h"

namespace tilth::registration {

class DepthToColor {
 public:
  static constexpr float kEdgeMarginPx = 1e-3f;

  // `file` names the calibration in errors.
  DepthToColor(const RigCalibration& rig, const std::string& file);

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

  int row_capacity() const { return row_capacity_; }  // depth width, whole SIMD vectors
  int depth_width() const { return depth_width_; }
  int depth_height() const { return depth_height_; }
  int color_width() const { return color_width_; }
  int color_height() const { return color_height_; }

 private:
  template <bool kSeparable, bool kDistorted>
  void project(int row, const float* z_mm, float* color_u, float* color_v,
               float* color_depth) const;

  int depth_width_;
  int depth_height_;
  int color_width_;
  int color_height_;
  int row_capacity_;
  // Undistorted normalised coordinates of the depth pixels. Without depth distortion x'
  // depends on u only and y' on v only (one row of x', one y' per row), which keeps
  // megabytes of tables out of the per-frame memory traffic; otherwise both are tables
  // of depth_height rows of row_capacity.
  bool separable_;
  std::vector<float> x_;
  std::vector<float> y_;
  std::array<float, 9> r_;  // row-major
  std::array<float, 3> t_mm_;
  float z_offset_mm_;
  float fx_, fy_, cx_, cy_;
  bool distorted_;
  std::array<float, 5> k_;
  float max_radius2_;  // squared normalised radius of the fold (infinity: none)
};

}  // namespace tilth::registration
