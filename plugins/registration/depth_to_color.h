// Where each depth pixel is seen in the colour image: the full projective mapping of
// spec/calibration.md with both cameras' lens distortion. The undistorted coordinates of
// the depth pixels are computed once per calibration; a frame costs a few multiply-adds
// and one division per pixel, four pixels at a time.
#pragma once

#include <array>
#include <cstdint>
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

  // The z-buffer's grid over the colour image: square cells of `size` pixels, `columns`
  // to a row.
  struct CellGrid {
    int size;
    int columns;
  };

  // As project_row, for the registration's first pass: the nearest colour pixel as its
  // index y * width + x, its cell (cell_y * columns + cell_x), both -1 where the colour
  // image does not show the point, and the depth along the colour axis (meaningful only
  // where shown). Indices are computed in float: the colour image must have fewer than
  // 2^24 pixels and a side below 2^16.
  void locate_row(int row, const float* z_mm, const CellGrid& cells, std::int32_t* color_pixel,
                  std::int32_t* cell, float* color_depth) const;
  // The depth along the colour axis alone, bit for bit as locate_row gives it, for the
  // second pass: a few multiply-adds per pixel, cheaper than keeping it from the first.
  void color_depth_row(int row, const float* z_mm, float* color_depth) const;

  int row_capacity() const { return row_capacity_; }  // depth width, whole SIMD vectors
  int depth_width() const { return depth_width_; }
  int depth_height() const { return depth_height_; }
  int color_width() const { return color_width_; }
  int color_height() const { return color_height_; }

 private:
  using Row3 = std::array<float, 3>;

  template <class Store>
  void project(int row, const float* z_mm, const Store& store) const;
  template <bool kSeparable, bool kDistorted, class Store>
  void project(int row, const float* z_mm, const Store& store) const;

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
  std::array<Row3, 3> r_;
  std::array<float, 3> t_mm_;
  // Without colour distortion: rows that take a point's P_d to (u + 0.5) Z and (v + 0.5) Z,
  // and the T parts of those.
  Row3 u_numerator_;
  Row3 v_numerator_;
  float u_numerator_t_;
  float v_numerator_t_;
  float z_offset_mm_;
  float fx_, fy_, cx_half_, cy_half_;  // cx + 0.5, cy + 0.5: see project()
  bool distorted_;
  std::array<float, 5> k_;
  float max_radius2_;  // squared normalised radius of the fold (infinity: none)
};

}  // namespace tilth::registration
