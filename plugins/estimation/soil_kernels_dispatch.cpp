// The levels of soil_kernels.cpp that were built (TILTH_KERNEL_LEVELS_X86_64: the x86-64
// ones, see cmake/TilthKernelLevels.cmake).
#include "soil_kernels.h"
#include "tilth/kernel_levels.h"

namespace tilth::estimation {

namespace baseline {
extern const SoilKernels kSoilKernels;
}
#ifdef TILTH_KERNEL_LEVELS_X86_64
namespace x86_64_v2 {
extern const SoilKernels kSoilKernels;
}
namespace x86_64_v3 {
extern const SoilKernels kSoilKernels;
}
namespace x86_64_v4 {
extern const SoilKernels kSoilKernels;
}
#endif

std::span<const SoilKernels* const> available_soil_kernels() {
  static const KernelLevels<SoilKernels> kLevels{
#ifdef TILTH_KERNEL_LEVELS_X86_64
      &x86_64_v4::kSoilKernels, &x86_64_v3::kSoilKernels, &x86_64_v2::kSoilKernels,
#endif
      &baseline::kSoilKernels};
  return kLevels.runnable();
}

}  // namespace tilth::estimation
