// The levels of residue_kernels.cpp that were built (TILTH_KERNEL_LEVELS_X86_64: the
// x86-64 ones, see cmake/TilthKernelLevels.cmake).
#include "residue_kernels.h"
#include "tilth/kernel_levels.h"

namespace tilth::segmentation {

namespace baseline {
extern const ResidueKernels kResidueKernels;
}
#ifdef TILTH_KERNEL_LEVELS_X86_64
namespace x86_64_v2 {
extern const ResidueKernels kResidueKernels;
}
namespace x86_64_v3 {
extern const ResidueKernels kResidueKernels;
}
namespace x86_64_v4 {
extern const ResidueKernels kResidueKernels;
}
#endif

std::span<const ResidueKernels* const> available_residue_kernels() {
  static const KernelLevels<ResidueKernels> kLevels{
#ifdef TILTH_KERNEL_LEVELS_X86_64
      &x86_64_v4::kResidueKernels, &x86_64_v3::kResidueKernels, &x86_64_v2::kResidueKernels,
#endif
      &baseline::kResidueKernels};
  return kLevels.runnable();
}

}  // namespace tilth::segmentation
