// count_kernels.h at one level: TILTH_KERNEL_LEVEL names the level's namespace.
#include <cstring>

#include "count_kernels.h"
#include "tilth/kernel_level.h"

namespace TILTH_KERNEL_LEVEL {
namespace {

constexpr int kLanes = tilth::kKernelLanes;
using Floats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Ints = int __attribute__((vector_size(kLanes * sizeof(int))));

int count_above(const float* values, int count, float threshold) {
  Ints counts{};
  int i = 0;
  for (; i + kLanes <= count; i += kLanes) {
    Floats v;
    std::memcpy(&v, values + i, sizeof v);
    counts -= v > threshold;  // true is -1
  }
  int total = 0;
  for (int lane = 0; lane < kLanes; ++lane) total += counts[lane];
  for (; i < count; ++i) total += values[i] > threshold ? 1 : 0;
  return total;
}

}  // namespace

extern const CountKernels kCountKernels{count_above, TILTH_KERNEL_LEVEL_NAME};

}  // namespace TILTH_KERNEL_LEVEL
