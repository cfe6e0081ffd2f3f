// The registration's per-row vector loops: projecting a row of depth pixels into the
// colour camera, and finding the sampler's pixels and the z-buffer cell of each point.
// row_kernels.cpp is compiled once per x86-64 level (baseline SSE2, v2 = SSE4.2, v3 =
// AVX2 + FMA, v4 = AVX-512) and row_kernels() picks the best the CPU runs, so the plugin runs on
// any x86-64 PC yet uses the widest vectors there are; other architectures get their baseline.
#pragma once

#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "color_sampler.h"

namespace tilth::registration {

// Rows are processed in whole vectors of the widest level: row capacities are multiples
// of this many pixels.
inline constexpr int kRowLanes = 16;

// The mapping of spec/calibration.md as the kernels read it (see DepthToColor).
struct ProjectionModel {
  int depth_width;
  int row_capacity;  // depth_width rounded up to whole vectors
  int color_width;
  int color_height;
  std::array<float, 9> r;  // depth to colour rotation, row-major
  std::array<float, 3> t_mm;
  float z_offset_mm;
  float fx, fy, cx, cy;  // colour camera
  bool distorted;        // colour lens distortion (k1, k2, p1, p2, k3)
  std::array<float, 5> k;
  float max_radius2;  // squared normalised radius of the distortion's fold
  float edge_margin_px;
};

// The z-buffer's cells: squares of `size` colour pixels, `columns` to a row, and one
// more cell, `outside`, for the points the colour image does not show.
struct CellGrid {
  int size;
  int columns;
  int outside;
};

struct RowKernels {
  // Depth row at z_mm (row_capacity values are written; z_mm holds depth_width): x and y
  // are the pixels' undistorted normalised coordinates, y null when it is row_y for the
  // whole row. Outputs: colour pixel (u, v) and depth along the colour axis, NaN where
  // the colour image does not show the point.
  void (*project)(const ProjectionModel& model, const float* x, const float* y, float row_y,
                  const float* z_mm, float* color_u, float* color_v, float* color_depth);
  // For `count` projected points: the sampler's pixel key (Addressing; clamped to the
  // image, so that a point not shown reads a pixel too) and the cell.
  void (*locate)(const Addressing& addressing, const CellGrid& cells, int color_width,
                 int color_height, int count, const float* color_u, const float* color_v,
                 const float* color_depth, int* keys, int* cell_indices);
  const char* level;  // "x86-64-v4", ...
};

// "auto" and the names of the levels built, widest first.
std::vector<std::string> row_kernel_levels();

// The levels this CPU runs, widest first.
std::span<const RowKernels* const> available_row_kernels();

// The level named `level`, or the widest for "auto". Throws tilth::Error naming the
// levels this CPU runs when it does not run `level`.
const RowKernels& row_kernels(std::string_view level);

}  // namespace tilth::registration
