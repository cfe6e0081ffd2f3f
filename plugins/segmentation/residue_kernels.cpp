// The loops of residue_kernels.h for one instruction-set level: CMake compiles this file
// once per level with -march=<level> and TILTH_KERNEL_LEVEL naming its namespace.
// Everything here stays in that namespace or is always inlined, so that no function
// compiled for one level can stand in for another's at link time.
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "kernel_levels/kernel_level.h"
#include "residue_kernels.h"
#include "tilth/messages/residue_mask.h"

static_assert(std::endian::native == std::endian::little, "a pixel's bytes are read as a word");

namespace tilth::segmentation::TILTH_KERNEL_LEVEL {
namespace {

// Floats and ints in one register of the level, GCC vector extensions.
constexpr int kLanes = kKernelLanes;
static_assert(64 % kLanes == 0, "a vector's pixels lie in one mask word");

using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Ints = std::int32_t __attribute__((vector_size(kLanes * sizeof(std::int32_t))));
using Bytes = std::uint8_t __attribute__((vector_size(kLanes)));

constexpr std::uint64_t kVectorBits = (std::uint64_t{1} << kLanes) - 1;

// Lane i: 1 << i, the lane's bit in a vector's bits.
template <std::size_t... kLane>
constexpr Ints lane_bits(std::index_sequence<kLane...>) {
  return Ints{(1 << kLane)...};
}
constexpr Ints kLaneBit = lane_bits(std::make_index_sequence<kLanes>());

#if defined(__AVX2__)
// With gathers: a vector of pixels at a time. Each pixel's 3 bytes are spread to a word
// b | g << 8 | r << 16, the colour's index in a table of every colour; g | r << 8 is the
// index of its run. (12 bytes, 4 pixels, go to each 128-bit lane, then a byte shuffle
// spreads them within the lane.)
constexpr int kPixelsPerLookup = kLanes;

[[gnu::always_inline]] inline __m128i spread_in_lane() {
  return _mm_setr_epi8(0, 1, 2, -1, 3, 4, 5, -1, 6, 7, 8, -1, 9, 10, 11, -1);
}

using Words = __m256i;

[[gnu::always_inline]] inline Words pixel_words(const std::uint8_t* bgr, int lanes) {
  __m256i raw;
  if (lanes == kLanes) {  // 24 bytes: 6 words
    raw = _mm256_maskload_epi32(reinterpret_cast<const int*>(bgr),
                                _mm256_setr_epi32(-1, -1, -1, -1, -1, -1, 0, 0));
  } else {
    std::uint8_t tail[32] = {};
    std::memcpy(tail, bgr, static_cast<std::size_t>(3 * lanes));
    raw = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(tail));
  }
  const __m256i spread =
      _mm256_permutevar8x32_epi32(raw, _mm256_setr_epi32(0, 1, 2, 0, 3, 4, 5, 0));
  return _mm256_shuffle_epi8(spread, _mm256_broadcastsi128_si256(spread_in_lane()));
}

[[gnu::always_inline]] inline std::uint64_t runs_contain(const BlueRun* runs, const Words& words) {
  const __m256i run =
      _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), reinterpret_cast<const int*>(runs),
                                  _mm256_srli_epi32(words, 8), _mm256_set1_epi32(-1), 2);
  const __m256i byte = _mm256_set1_epi32(0xff);
  const __m256i blue = _mm256_and_si256(words, byte);
  const __m256i first = _mm256_and_si256(run, byte);
  const __m256i last = _mm256_and_si256(_mm256_srli_epi32(run, 8), byte);
  const __m256i out =
      _mm256_or_si256(_mm256_cmpgt_epi32(first, blue), _mm256_cmpgt_epi32(blue, last));
  return static_cast<std::uint8_t>(~_mm256_movemask_ps(_mm256_castsi256_ps(out)));
}

[[gnu::always_inline]] inline std::uint64_t table_contains(const std::uint8_t* table,
                                                           const Words& words) {
  const __m256i entry = _mm256_mask_i32gather_epi32(
      _mm256_setzero_si256(), reinterpret_cast<const int*>(table), words, _mm256_set1_epi32(-1), 1);
  const __m256i out =
      _mm256_cmpeq_epi32(_mm256_and_si256(entry, _mm256_set1_epi32(0xff)), _mm256_setzero_si256());
  return static_cast<std::uint8_t>(~_mm256_movemask_ps(_mm256_castsi256_ps(out)));
}

#else
// Without gathers: a pixel at a time, its bytes where they are.
constexpr int kPixelsPerLookup = 1;

[[gnu::always_inline]] inline const std::uint8_t* pixel_words(const std::uint8_t* bgr, int) {
  return bgr;
}

// Whether a pixel's colour is in the box.
[[gnu::always_inline]] inline bool runs_contain(const BlueRun* runs, const std::uint8_t* pixel) {
  const BlueRun run = runs[pixel[1] | pixel[2] << 8];
  return pixel[0] >= (run & 0xff) && pixel[0] <= (run >> 8);
}

[[gnu::always_inline]] inline bool table_contains(const std::uint8_t* table,
                                                  const std::uint8_t* pixel) {
  return table[pixel[0] | pixel[1] << 8 | pixel[2] << 16] != 0;
}
#endif

// bits for `count` pixels from bgr on; in(pixel_words(...)) gives the in-range bits of
// kPixelsPerLookup pixels.
template <class In>
[[gnu::always_inline]] inline void classify(const std::uint8_t* bgr, int count, std::uint64_t* bits,
                                            In in) {
  for (int x = 0; x < count; x += 64) {
    const int pixels = count - x < 64 ? count - x : 64;
    std::uint64_t word = 0;
    for (int i = 0; i < pixels; i += kPixelsPerLookup) {
      const int lanes = pixels - i < kPixelsPerLookup ? pixels - i : kPixelsPerLookup;
      const std::uint64_t inside = in(pixel_words(bgr + 3 * (x + i), lanes));
      word |= (inside & ((std::uint64_t{1} << lanes) - 1)) << i;
    }
    bits[x / 64] = word;
  }
}

void in_runs(const BlueRun* runs, const std::uint8_t* bgr, int count, std::uint64_t* bits) {
  classify(
      bgr, count, bits, [runs](const auto& pixels) __attribute__((always_inline)) {
        return runs_contain(runs, pixels);
      });
}

void in_table(const std::uint8_t* table, const std::uint8_t* bgr, int count, std::uint64_t* bits) {
  classify(
      bgr, count, bits, [table](const auto& pixels) __attribute__((always_inline)) {
        return table_contains(table, pixels);
      });
}

void write_residue_row(const std::uint64_t* unknown, const std::uint64_t* residue,
                       const float* depth_mm, int cols, std::uint8_t* mask, float* soil_mm) {
  constexpr float kNoSoil = std::numeric_limits<float>::quiet_NaN();
  const Floats no_soil = Floats{} + kNoSoil;
  const Ints unknown_code = Ints{} + ResidueMask::kUnknown;
  const Ints residue_code = Ints{} + ResidueMask::kResidue;
  const Ints soil_code = Ints{} + ResidueMask::kSoil;
  int x = 0;
  for (; x + kLanes <= cols; x += kLanes) {
    const int word = x / 64, shift = x % 64;
    const Ints unknown_bits = Ints{} + static_cast<int>((unknown[word] >> shift) & kVectorBits);
    const Ints residue_bits = Ints{} + static_cast<int>((residue[word] >> shift) & kVectorBits);
    Floats depth;
    std::memcpy(&depth, depth_mm + x, sizeof depth);
    const Ints is_unknown = ((unknown_bits & kLaneBit) != 0) | (depth != depth);
    const Ints is_residue = (residue_bits & kLaneBit) != 0;
    const Ints code = is_unknown ? unknown_code : is_residue ? residue_code : soil_code;
    const Bytes codes = __builtin_convertvector(code, Bytes);
    std::memcpy(mask + x, &codes, sizeof codes);
    const Floats soil = is_unknown | is_residue ? no_soil : depth;
    std::memcpy(soil_mm + x, &soil, sizeof soil);
  }
  for (; x < cols; ++x) {
    const bool is_unknown = ((unknown[x / 64] >> (x % 64)) & 1) || depth_mm[x] != depth_mm[x];
    const bool is_residue = (residue[x / 64] >> (x % 64)) & 1;
    mask[x] = is_unknown   ? ResidueMask::kUnknown
              : is_residue ? ResidueMask::kResidue
                           : ResidueMask::kSoil;
    soil_mm[x] = is_unknown || is_residue ? kNoSoil : depth_mm[x];
  }
}

}  // namespace

extern const ResidueKernels kResidueKernels{in_runs, in_table, write_residue_row,
                                            TILTH_KERNEL_LEVEL_NAME};

}  // namespace tilth::segmentation::TILTH_KERNEL_LEVEL
