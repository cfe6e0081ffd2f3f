// The levels of count_kernels.cpp that were built (TILTH_KERNEL_LEVELS_X86_64: the x86-64
// ones).
#include "count_kernels.h"
#include "tilth/kernel_levels.h"

namespace baseline {
extern const CountKernels kCountKernels;
}
#ifdef TILTH_KERNEL_LEVELS_X86_64
namespace x86_64_v2 {
extern const CountKernels kCountKernels;
}
namespace x86_64_v3 {
extern const CountKernels kCountKernels;
}
namespace x86_64_v4 {
extern const CountKernels kCountKernels;
}
#endif

std::span<const CountKernels* const> available_count_kernels() {
  static const tilth::KernelLevels<CountKernels> kLevels{
#ifdef TILTH_KERNEL_LEVELS_X86_64
      &x86_64_v4::kCountKernels, &x86_64_v3::kCountKernels, &x86_64_v2::kCountKernels,
#endif
      &baseline::kCountKernels};
  return kLevels.runnable();
}
