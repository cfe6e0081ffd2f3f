// The loop of soil_kernels.h for one instruction-set level: CMake compiles this file once
// per level with -march=<level> and TILTH_KERNEL_LEVEL naming its namespace. Everything
// here stays in that namespace, so that no function compiled for one level can stand in
// for another's at link time.
#include <cstring>
#include <limits>

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

#include "soil_kernels.h"
#include "tilth/kernel_level.h"

namespace tilth::estimation::TILTH_KERNEL_LEVEL {
namespace {

constexpr int kLanes = kKernelLanes;
static_assert(kLanes <= kSlack, "a whole-vector store fits the slack");

using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Ints = int __attribute__((vector_size(kLanes * sizeof(int))));

constexpr float kLargest = std::numeric_limits<float>::max();

// A vector at a time, the range in vectors with the other lanes held at the far end.
// With AVX-512 a vector's finite depths are compressed together and stored whole; below,
// soil and residue come in patches, so a vector's depths are mostly all finite (stored
// whole) or none, and a mixed one is stored a depth at a time.
CollectedDepths collect_finite(const float* depth_mm, int count, CollectedDepths collected) {
  float* out = collected.end;
  const Floats largest = Floats{} + kLargest;
  const Floats smallest = Floats{} - kLargest;
  Floats low = largest;
  Floats high = smallest;
  int i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    Floats depth;
    std::memcpy(&depth, depth_mm + i, sizeof depth);
    const Floats magnitude = depth < 0 ? -depth : depth;
    const Ints finite = magnitude <= largest;  // NaN, inf: false
    low = finite && depth < low ? depth : low;
    high = finite && depth > high ? depth : high;
#if defined(__AVX512F__)
    const __mmask16 lanes = _mm512_movepi32_mask(reinterpret_cast<__m512i>(finite));
    _mm512_storeu_ps(out, _mm512_maskz_compress_ps(lanes, reinterpret_cast<__m512>(depth)));
    out += __builtin_popcount(lanes);
#else
    bool all = true, none = true;
    for (int lane = 0; lane < kLanes; ++lane) {
      all = all && finite[lane] != 0;
      none = none && finite[lane] == 0;
    }
    if (all) {
      std::memcpy(out, &depth, sizeof depth);
      out += kLanes;
    } else if (!none) {
      for (int lane = 0; lane < kLanes; ++lane) {
        *out = depth[lane];
        out += finite[lane] != 0 ? 1 : 0;
      }
    }
#endif
  }
  float lowest = collected.lowest, highest = collected.highest;
  for (int lane = 0; lane < kLanes; ++lane) {
    lowest = low[lane] < lowest ? low[lane] : lowest;
    highest = high[lane] > highest ? high[lane] : highest;
  }
  for (; i < count; ++i) {
    const float depth = depth_mm[i];
    const float magnitude = depth < 0 ? -depth : depth;
    if (!(magnitude <= kLargest)) continue;
    *out++ = depth;
    lowest = depth < lowest ? depth : lowest;
    highest = depth > highest ? depth : highest;
  }
  return {out, lowest, highest};
}

}  // namespace

extern const SoilKernels kSoilKernels{collect_finite, TILTH_KERNEL_LEVEL_NAME};

}  // namespace tilth::estimation::TILTH_KERNEL_LEVEL
