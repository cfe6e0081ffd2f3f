// The registration's per-row vector loops: projecting a row of depth pixels into the
// colour camera; finding each point's colour pixels and z-buffer cell and keeping the
// nearest point of each cell; and, once every row is in the z-buffer, each point's status
// and nearest-sampled colour.
// row_kernels.cpp is compiled for the x86-64 baseline (SSE2) and x86-64-v3 (AVX2 + FMA),
// and row_kernels() picks the best the CPU runs, so the plugin runs on any x86-64 PC yet
// uses AVX2 where there is one; other architectures get their baseline.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pixel_word.h"

namespace tilth::registration {

// Rows are processed in whole vectors of the widest level: row capacities are multiples
// of this many pixels.
inline constexpr int kRowLanes = 16;

// The mapping of docs/formats/calibration.md as the kernels read it (see DepthToColor).
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

// The z-buffer's cells: squares of `size` colour pixels, `columns` to a row, and one more
// cell, `outside`, for the points the colour image does not show.
struct CellGrid {
  int size;
  int columns;
  int outside;

  int count() const { return outside + 1; }
};

// What decides a located point's status, and the status codes (RegisteredColor's).
struct Visibility {
  const float* nearest_mm;  // the z-buffer, per cell
  int outside;              // CellGrid::outside
  float tolerance_mm;       // occlusion_tolerance_mm
  std::uint8_t valid, no_depth, outside_color, occluded;
};

struct RowKernels {
  // Depth row at z_mm (row_capacity values are written; z_mm holds depth_width): x and y
  // are the pixels' undistorted normalised coordinates, y null when it is row_y for the
  // whole row. Outputs: colour pixel (u, v) and depth along the colour axis, NaN where
  // the colour image does not show the point.
  void (*project)(const ProjectionModel& model, const float* x, const float* y, float row_y,
                  const float* z_mm, float* color_u, float* color_v, float* color_depth);
  // For `count` projected points (a multiple of kRowLanes): the key of the pixels
  // nearest sampling reads (Addressing; clamped to the image, so that a point not shown
  // reads pixels too) and the cell.
  void (*locate)(const Addressing& addressing, const CellGrid& cells, int color_width,
                 int color_height, int count, const float* color_u, const float* color_v,
                 const float* color_depth, int* keys, int* cell_indices);
  // nearest_mm (CellGrid::count() floats) lowered to the depth of each of `count`
  // located points (a multiple of kRowLanes) in its cell. Points not shown (NaN depth)
  // are passed over: with a window of the colour sensor most of a row is not shown, and
  // lowering their one cell again and again would chain every load to the last store.
  void (*keep_nearest)(const CellGrid& cells, int count, const float* color_depth,
                       const int* cell_indices, float* nearest_mm);
  // For `count` located points of a depth row at z_mm: status (Visibility) and, where
  // valid, the colour at the key's pixels (blue, green, red; the mean of a quad's
  // greens), else black. Reads whole vectors of the located arrays; writes `count`
  // statuses and 3 * `count` bytes.
  void (*resolve)(const Visibility& visibility, const PixelWord& pixels, int count,
                  const float* z_mm, const float* color_depth, const int* cell_indices,
                  const int* keys, std::uint8_t* status, std::uint8_t* bgr);
  const char* level;  // "x86-64-v3", "baseline"
};

// "auto" and the names of the levels built, widest first.
std::vector<std::string> row_kernel_levels();

// The levels this CPU runs, widest first.
std::span<const RowKernels* const> available_row_kernels();

// The level named `level`, or the widest for "auto". Throws tilth::Error naming the
// levels this CPU runs when it does not run `level`.
const RowKernels& row_kernels(std::string_view level);

}  // namespace tilth::registration
