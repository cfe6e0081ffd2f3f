// The loops of row_kernels.h for one instruction-set level: CMake compiles this file once
// per level with -march=<level> and TILTH_KERNEL_LEVEL naming its namespace. Everything
// here stays in that namespace or is always inlined, so that no function compiled for
// one level can stand in for another's at link time.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

#include "lens_model.h"
#include "row_kernels.h"

#ifndef TILTH_KERNEL_LEVEL
#error "compile with TILTH_KERNEL_LEVEL (the namespace) and TILTH_KERNEL_LEVEL_NAME"
#endif

namespace tilth::registration::TILTH_KERNEL_LEVEL {
namespace {

// Floats and ints in one register of the level, GCC vector extensions. Vectors wider
// than the registers would be split up, and some operations one lane at a time.
#if defined(__AVX512F__)
constexpr int kLanes = 16;
#elif defined(__AVX__)
constexpr int kLanes = 8;
#else
constexpr int kLanes = 4;  // SSE2, SSE4.2, NEON
#endif
static_assert(kRowLanes % kLanes == 0, "rows are whole vectors of every level");

using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Ints = std::int32_t __attribute__((vector_size(kLanes * sizeof(std::int32_t))));

// Vectors go by reference: returned by value they would be passed differently per level.
void load(Floats& v, const float* values) { std::memcpy(&v, values, sizeof v); }
void store(float* values, const Floats& v) { std::memcpy(values, &v, sizeof v); }
void store(int* values, const Ints& v) { std::memcpy(values, &v, sizeof v); }

Floats splat(float value) { return Floats{} + value; }

// The model's numbers as vectors, held in registers: loop stores through float pointers
// could alias the model, so its fields would be loaded again for every vector.
template <bool kSeparable, bool kDistorted>
void project_vectors(const ProjectionModel& m, const float* xs, const float* ys, float row_y,
                     const float* z_mm, float* color_u, float* color_v, float* color_depth) {
  // Without depth distortion y' is the row's: R * (x', y', 1) = column 0 * x' + a constant.
  const Floats r00 = splat(m.r[0]), r01 = splat(m.r[1]), r02 = splat(m.r[1] * row_y + m.r[2]);
  const Floats r10 = splat(m.r[3]), r11 = splat(m.r[4]), r12 = splat(m.r[4] * row_y + m.r[5]);
  const Floats r20 = splat(m.r[6]), r21 = splat(m.r[7]), r22 = splat(m.r[7] * row_y + m.r[8]);
  const Floats tx = splat(m.t_mm[0]), ty = splat(m.t_mm[1]), tz = splat(m.t_mm[2]);
  const Floats z_offset = splat(m.z_offset_mm);
  const Floats fx = splat(m.fx), fy = splat(m.fy), cx = splat(m.cx), cy = splat(m.cy);
  const Floats zero = splat(0.0f), one = splat(1.0f), minus_half = splat(-0.5f);
  const Floats u_end = splat(static_cast<float>(m.color_width) - 0.5f - m.edge_margin_px);
  const Floats v_end = splat(static_cast<float>(m.color_height) - 0.5f - m.edge_margin_px);
  const Floats max_radius2 = splat(m.max_radius2);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const Floats not_shown = splat(nan);
  const lens::Distortion<Floats> distortion{
      splat(m.k[0]), splat(m.k[1]), splat(m.k[2]), splat(m.k[3]), splat(m.k[4]), one, splat(2.0f)};
  const int width = m.depth_width;
  const int capacity = m.row_capacity;

  for (int i = 0; i < capacity; i += kLanes) {
    Floats z;
    if (i + kLanes <= width) {
      load(z, z_mm + i);
    } else {  // the row's last, partial vector: no reading past its end
      float tail[kLanes];
      for (int lane = 0; lane < kLanes; ++lane)
        tail[lane] = i + lane < width ? z_mm[i + lane] : nan;
      load(z, tail);
    }
    const Floats depth = z + z_offset;  // at the ToF optical centre
    Floats x;
    load(x, xs + i);
    Floats rx = r00 * x + r02;
    Floats ry = r10 * x + r12;
    Floats rz = r20 * x + r22;
    if constexpr (!kSeparable) {
      Floats y;
      load(y, ys + i);
      rx += r01 * y;
      ry += r11 * y;
      rz += r21 * y;
    }
    // P_c = R * (depth * (x', y', 1)) + T
    const Floats pz = depth * rz + tz;
    const Floats inverse = one / pz;
    Floats nx = (depth * rx + tx) * inverse;
    Floats ny = (depth * ry + ty) * inverse;
    Ints shown = pz > zero;  // NaN compares false: no depth is not shown
    if constexpr (kDistorted) {
      shown &= nx * nx + ny * ny <= max_radius2;
      distortion.apply(nx, ny);
    }
    const Floats u = fx * nx + cx;
    const Floats v = fy * ny + cy;
    shown &= (u >= minus_half) & (u < u_end) & (v >= minus_half) & (v < v_end);
    store(color_u + i, u);
    store(color_v + i, v);
    store(color_depth + i, shown ? pz : not_shown);
  }
}

void project(const ProjectionModel& m, const float* xs, const float* ys, float row_y,
             const float* z_mm, float* color_u, float* color_v, float* color_depth) {
  // Compile-time variants keep the per-vector loop free of branches.
  const auto run = [&]<bool kSeparable>() {
    m.distorted
        ? project_vectors<kSeparable, true>(m, xs, ys, row_y, z_mm, color_u, color_v, color_depth)
        : project_vectors<kSeparable, false>(m, xs, ys, row_y, z_mm, color_u, color_v, color_depth);
  };
  ys == nullptr ? run.template operator()<true>() : run.template operator()<false>();
}

// The sampler's top-left pixel x = floor(u + (1 - span) / 2 + 0.5) = trunc(u + 2 -
// span / 2) - 1, clamped in float (NaN clamps too), where the truncation is a floor.
void locate(const Addressing& addressing, const CellGrid& cells, int color_width, int color_height,
            int count, const float* color_u, const float* color_v, const float* color_depth,
            int* keys, int* cell_indices) {
  const Floats start = splat(2.0f - 0.5f * static_cast<float>(addressing.span));
  const Floats lowest = splat(1.0f);
  const Floats x_end = splat(static_cast<float>(color_width - addressing.span + 1));
  const Floats y_end = splat(static_cast<float>(color_height - addressing.span + 1));
  const Floats half = splat(0.5f);
  const Floats per_cell = splat(1.0f / static_cast<float>(cells.size));
  const Ints zeros{};
  const Ints row_key = zeros + addressing.row_key, column_key = zeros + addressing.column_key;
  const Ints odd_row = zeros + addressing.odd_row, odd_column = zeros + addressing.odd_column;
  const Ints columns = zeros + cells.columns, outside = zeros + cells.outside;
  for (int i = 0; i < count; i += kLanes) {
    Floats u, v, depth;
    load(u, color_u + i);
    load(v, color_v + i);
    load(depth, color_depth + i);
    Floats xf = u + start, yf = v + start;
    xf = xf > lowest ? xf : lowest;
    yf = yf > lowest ? yf : lowest;
    xf = xf < x_end ? xf : x_end;
    yf = yf < y_end ? yf : y_end;
    const Ints x = __builtin_convertvector(xf, Ints) - 1;
    const Ints y = __builtin_convertvector(yf, Ints) - 1;
    store(keys + i, y * row_key + x * column_key + (-(y & 1) & odd_row) + (-(x & 1) & odd_column));
    // Shown points have -0.5 <= u < width - 0.5: u + 0.5 truncates to its floor.
    const Ints cell = __builtin_convertvector((v + half) * per_cell, Ints) * columns +
                      __builtin_convertvector((u + half) * per_cell, Ints);
    store(cell_indices + i, depth == depth ? cell : outside);  // NaN: not shown
  }
}

}  // namespace

extern const RowKernels kRowKernels{project, locate, TILTH_KERNEL_LEVEL_NAME};

}  // namespace tilth::registration::TILTH_KERNEL_LEVEL
