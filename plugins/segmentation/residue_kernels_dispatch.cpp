// The levels of residue_kernels.cpp that were built (see libs/kernel_levels/KernelLevels.cmake).
#include "kernel_levels/kernel_levels.h"
#include "residue_kernels.h"

namespace tilth::segmentation {

TILTH_KERNEL_LEVELS(ResidueKernels, kResidueKernels, residue_kernel_levels)

std::span<const ResidueKernels* const> available_residue_kernels() {
  return residue_kernel_levels().runnable();
}

}  // namespace tilth::segmentation
