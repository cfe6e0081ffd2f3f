// The loops of row_kernels.h for one instruction-set level: CMake compiles this file once
// per level with -march=<level> and TILTH_KERNEL_LEVEL naming its namespace. Everything
// here stays in that namespace or is always inlined, so that no function compiled for
// one level can stand in for another's at link time.
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "camera_geometry/lens_model.h"
#include "kernel_levels/kernel_level.h"
#include "row_kernels.h"

static_assert(std::endian::native == std::endian::little, "pixels' bytes are read as words");

namespace tilth::registration::TILTH_KERNEL_LEVEL {
namespace {

// Floats and ints in one register of the level, GCC vector extensions. Vectors wider
// than the registers would be split up, and some operations one lane at a time.
constexpr int kLanes = kKernelLanes;
static_assert(kRowLanes % kLanes == 0, "rows are whole vectors of every level");

using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Ints = std::int32_t __attribute__((vector_size(kLanes * sizeof(std::int32_t))));
using Words = std::uint32_t __attribute__((vector_size(kLanes * sizeof(std::uint32_t))));
using Bytes = std::uint8_t __attribute__((vector_size(kLanes)));
using WordBytes = std::uint8_t __attribute__((vector_size(kLanes * sizeof(std::uint32_t))));

// Vectors go by reference: returned by value they would be passed differently per level.
void load(Floats& v, const float* values) { std::memcpy(&v, values, sizeof v); }
#if defined(__AVX2__)  // below AVX2 the vectors read are floats only
void load(Ints& v, const int* values) { std::memcpy(&v, values, sizeof v); }
#endif
void store(float* values, const Floats& v) { std::memcpy(values, &v, sizeof v); }
void store(int* values, const Ints& v) { std::memcpy(values, &v, sizeof v); }

Floats splat(float value) { return Floats{} + value; }

// Lane i of a vector as an index vector built from i: the masks of __builtin_shuffle.
template <class Vector, class Lane, std::size_t... kLane>
constexpr Vector lanes_of(Lane lane, std::index_sequence<kLane...>) {
  return Vector{lane(static_cast<int>(kLane))...};
}
template <class Vector, int kCount = kLanes, class Lane>
constexpr Vector lanes_of(Lane lane) {
  return lanes_of<Vector>(lane, std::make_index_sequence<kCount>());
}

// With AVX2 the second pass is vectors (resolve_vectors); below, one pixel at a time
// (resolve_pixels).
#if defined(__AVX2__)
// base[index] for each lane; the 32-bit words at base + offset. (The masked gathers,
// from zeros: GCC 12's unmasked ones start from an undefined vector and warn.)
[[gnu::always_inline]] inline void gather(Floats& values, const float* base, const Ints& index) {
  const __m256 all = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  values = reinterpret_cast<Floats>(_mm256_mask_i32gather_ps(
      _mm256_setzero_ps(), base, reinterpret_cast<__m256i>(index), all, 4));
}
[[gnu::always_inline]] inline void gather_words(Words& words, const std::uint8_t* base,
                                                const Ints& offset) {
  words = reinterpret_cast<Words>(
      _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(base),
                                  reinterpret_cast<__m256i>(offset), _mm256_set1_epi32(-1), 1));
}
#endif

// 1 / x to within 2 float ulps: the vector division takes 8 to 10 cycles a vector where
// the hardware's estimate, refined by one Newton-Raphson step, takes 3 instructions. x =
// 0 gives NaN, where the division gives infinity; the projection does not show either.
[[gnu::always_inline]] inline Floats reciprocal(const Floats& x) {
#if defined(__AVX2__)
  const Floats estimate = reinterpret_cast<Floats>(_mm256_rcp_ps(reinterpret_cast<__m256>(x)));
  return estimate * (2.0f - x * estimate);
#else
  return 1.0f / x;
#endif
}

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
  constexpr float nan = std::numeric_limits<float>::quiet_NaN();
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
    const Floats inverse = reciprocal(pz);
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

// How a pixel word holds its colour: as blue | green << 8 | red << 16 already (bgr8), as
// one pixel's bytes in any order, or as a 2x2 quad.
enum class WordKind { kBgr, kPixel, kQuad };

WordKind word_kind(const PixelWord& pixels) {
  if (pixels.second_row != 0) return WordKind::kQuad;
  const auto& sites = pixels.sites;
  const bool bgr = sites[0] == 0 && sites[1] == 1 && sites[2] == 1 && sites[3] == 2;
  return pixels.phase_mask == 0 && bgr ? WordKind::kBgr : WordKind::kPixel;
}

#if defined(__AVX2__)
// The 4 bytes at base + offset for each lane, never reading past base + last + 3: a word
// is read from at most `last` and shifted down to the bytes wanted. Offsets are >= 0.
[[gnu::always_inline]] inline void read_words(Words& words, const std::uint8_t* base,
                                              const Ints& offset, const Ints& last) {
  const Ints start = offset < last ? offset : last;
  gather_words(words, base, start);
  words >>= reinterpret_cast<Words>((offset - start) << 3);
}

// The colour of each lane's key as blue | green << 8 | red << 16.
template <WordKind kKind>
[[gnu::always_inline]] inline void read_colors(Words& colors, const PixelWord& pixels,
                                               const Ints& key) {
  const Ints offset = key >> pixels.key_shift;
  const Ints last = Ints{} + static_cast<int>(pixels.size - 4);
  Words word;
  read_words(word, pixels.data, offset, last);
  if constexpr (kKind == WordKind::kBgr) {
    colors = word & 0xffffffu;
  } else {
    if constexpr (kKind == WordKind::kQuad) {
      Words second;
      read_words(second, pixels.data, offset + static_cast<int>(pixels.second_row), last);
      word = (word & 0xffffu) | (second << 16);
    }
    const Words phase = reinterpret_cast<Words>(key & pixels.phase_mask);
    const auto channel = [&](int site) {
      return (word >> ((phase ^ static_cast<std::uint32_t>(site)) << 3)) & 0xffu;
    };
    const Words green = (channel(pixels.sites[1]) + channel(pixels.sites[2]) + 1) >> 1;
    colors = channel(pixels.sites[0]) | (green << 8) | (channel(pixels.sites[3]) << 16);
  }
}

// Each lane's blue, green and red bytes, packed: the 3 low bytes of each word within each
// 16-byte block, then the blocks' 12 bytes together; `bytes` of them written.
[[gnu::always_inline]] inline void pack_bgr(std::uint8_t* bgr, const Words& colors, int bytes) {
  constexpr WordBytes kInBlocks = lanes_of<WordBytes, 4 * kLanes>([](int byte) {
    const int block = byte / 16, in_block = byte % 16;
    return in_block < 12 ? block * 16 + in_block / 3 * 4 + in_block % 3 : byte;
  });
  constexpr Ints kBlocksTogether = lanes_of<Ints>(
      [](int word) { return word < kLanes / 4 * 3 ? word / 3 * 4 + word % 3 : word; });
  const WordBytes in_blocks = __builtin_shuffle(reinterpret_cast<WordBytes>(colors), kInBlocks);
  const Ints packed = __builtin_shuffle(reinterpret_cast<Ints>(in_blocks), kBlocksTogether);
  std::memcpy(bgr, &packed, static_cast<std::size_t>(bytes));
}

template <WordKind kKind>
void resolve_vectors(const Visibility& visibility, const PixelWord& pixels, int count,
                     const float* z_mm, const float* color_depth, const int* cell_indices,
                     const int* keys, std::uint8_t* status, std::uint8_t* bgr) {
  const Ints zeros{};
  const Floats tolerance = splat(visibility.tolerance_mm);
  const Ints outside = zeros + visibility.outside;
  const Ints valid = zeros + visibility.valid, no_depth = zeros + visibility.no_depth;
  const Ints outside_color = zeros + visibility.outside_color;
  const Ints occluded = zeros + visibility.occluded;
  // `lanes` pixels from i on, writing `bgr_bytes` of colour.
  const auto resolve_lanes = [&](int i, int lanes, int bgr_bytes) __attribute__((always_inline)) {
    Floats z;
    if (lanes == kLanes) {
      load(z, z_mm + i);
    } else {  // the row's last, partial vector: no reading past its end
      float tail[kLanes] = {};
      std::memcpy(tail, z_mm + i, static_cast<std::size_t>(lanes) * sizeof(float));
      load(z, tail);
    }
    Floats depth, nearest;
    Ints cell, key;
    load(depth, color_depth + i);
    load(cell, cell_indices + i);
    load(key, keys + i);
    gather(nearest, visibility.nearest_mm, cell);
    const Ints visible = depth <= nearest + tolerance;  // NaN compares false
    const Ints code = visible           ? valid
                      : cell != outside ? occluded
                      : z != z          ? no_depth
                                        : outside_color;
    const Bytes codes = __builtin_convertvector(code, Bytes);
    std::memcpy(status + i, &codes, static_cast<std::size_t>(lanes));
    Words colors;
    read_colors<kKind>(colors, pixels, key);
    pack_bgr(bgr + 3 * i, colors & reinterpret_cast<Words>(visible), bgr_bytes);
  };
  // While a whole vector follows, a vector's colours are written as whole words: their
  // last kLanes bytes are junk that the next vector overwrites.
  int i = 0;
  for (; i + 2 * kLanes <= count; i += kLanes) resolve_lanes(i, kLanes, 4 * kLanes);
  for (; i < count; i += kLanes) {
    const int lanes = count - i < kLanes ? count - i : kLanes;
    resolve_lanes(i, lanes, 3 * lanes);
  }
}

#endif

// Without gathers and per-lane shifts (below AVX2): one pixel at a time, reading its
// bytes where a table per channel and phase of the key places them.
template <WordKind kKind>
void resolve_pixels(const Visibility& visibility, const PixelWord& pixels, int count,
                    const float* z_mm, const float* color_depth, const int* cell_indices,
                    const int* keys, std::uint8_t* status, std::uint8_t* bgr) {
  // Everything read per pixel in locals: through the byte pointers written, the compiler
  // must assume any memory changed, and would read the structs' fields again.
  const float* const nearest_mm = visibility.nearest_mm;
  const float tolerance_mm = visibility.tolerance_mm;
  const int outside = visibility.outside;
  const std::uint8_t valid = visibility.valid, occluded = visibility.occluded;
  const std::uint8_t no_depth = visibility.no_depth, outside_color = visibility.outside_color;
  const std::uint8_t* const data = pixels.data;
  const int key_shift = pixels.key_shift, phase_mask = pixels.phase_mask;
  // Per channel (blue, the greens, red) and phase (at most 3), its byte from the key's
  // first: channel-major, so that a phase indexes each channel's offsets directly.
  std::ptrdiff_t offsets[4][4];
  for (int channel = 0; channel < 4; ++channel) {
    for (int phase = 0; phase <= phase_mask; ++phase) {
      const int site = pixels.sites[static_cast<std::size_t>(channel)] ^ phase;
      offsets[channel][phase] =
          kKind == WordKind::kQuad ? (site & 1) + (site >> 1) * pixels.second_row : site;
    }
  }
  // The colour at `key` as blue | green << 8 | red << 16.
  const auto color_at = [&](int key) __attribute__((always_inline))->std::uint32_t {
    const std::uint8_t* const p = data + (key >> key_shift);
    if constexpr (kKind == WordKind::kBgr) {
      return p[0] | p[1] << 8 | p[2] << 16;
    } else {
      const int phase = key & phase_mask;
      const auto channel = [&](int channel) { return int{p[offsets[channel][phase]]}; };
      return channel(0) | ((channel(1) + channel(2) + 1) >> 1) << 8 | channel(3) << 16;
    }
  };
  // The status of pixel u, and its colour if valid, else black.
  const auto resolve_pixel = [&](int u) __attribute__((always_inline)) {
    const int cell = cell_indices[u];
    const bool visible = color_depth[u] <= nearest_mm[cell] + tolerance_mm;
    status[u] = visible              ? valid
                : cell != outside    ? occluded
                : z_mm[u] != z_mm[u] ? no_depth
                                     : outside_color;
    return color_at(keys[u]) & (visible ? 0xffffffu : 0u);
  };
  // While a pixel follows, a colour is written as a whole word: its last byte is junk
  // that the next pixel overwrites.
  for (int u = 0; u + 1 < count; ++u) {
    const std::uint32_t color = resolve_pixel(u);
    std::memcpy(bgr + 3 * u, &color, 4);
  }
  if (count > 0) {
    const std::uint32_t color = resolve_pixel(count - 1);
    std::memcpy(bgr + 3 * (count - 1), &color, 3);
  }
}

void resolve(const Visibility& visibility, const PixelWord& pixels, int count, const float* z_mm,
             const float* color_depth, const int* cell_indices, const int* keys,
             std::uint8_t* status, std::uint8_t* bgr) {
#if defined(__AVX2__)
  const auto run = [&]<WordKind kKind>() {
    resolve_vectors<kKind>(visibility, pixels, count, z_mm, color_depth, cell_indices, keys, status,
                           bgr);
  };
#else
  const auto run = [&]<WordKind kKind>() {
    resolve_pixels<kKind>(visibility, pixels, count, z_mm, color_depth, cell_indices, keys, status,
                          bgr);
  };
#endif
  switch (word_kind(pixels)) {
    case WordKind::kBgr:
      return run.template operator()<WordKind::kBgr>();
    case WordKind::kPixel:
      return run.template operator()<WordKind::kPixel>();
    case WordKind::kQuad:
      return run.template operator()<WordKind::kQuad>();
  }
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
    // Shown points have -0.5 <= u < width - 0.5: u + 0.5 truncates to its floor. A point
    // not shown (NaN) converts to INT_MIN, whose product with the columns overflows: the
    // cell is computed in unsigned (wrapping) arithmetic and replaced by the outside cell.
    const Words row = reinterpret_cast<Words>(__builtin_convertvector((v + half) * per_cell, Ints));
    const Words column =
        reinterpret_cast<Words>(__builtin_convertvector((u + half) * per_cell, Ints));
    const Ints cell = reinterpret_cast<Ints>(row * reinterpret_cast<Words>(columns) + column);
    store(cell_indices + i, depth == depth ? cell : outside);  // NaN: not shown
  }
}

// One point at a time: listing a vector's runs of points that share a cell costs more
// than waiting for a neighbour's store (measured). NaN depth leaves a cell as it was.
void keep_nearest(const CellGrid& cells, int count, const float* color_depth,
                  const int* cell_indices, float* nearest_mm) {
  for (int i = 0; i < count; ++i) {
    if (cell_indices[i] == cells.outside) continue;
    float& nearest = nearest_mm[cell_indices[i]];
    nearest = color_depth[i] < nearest ? color_depth[i] : nearest;
  }
}

}  // namespace

extern const RowKernels kRowKernels{project, locate, keep_nearest, resolve,
                                    TILTH_KERNEL_LEVEL_NAME};

}  // namespace tilth::registration::TILTH_KERNEL_LEVEL
