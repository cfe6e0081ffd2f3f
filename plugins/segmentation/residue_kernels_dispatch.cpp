// The levels of residue_kernels.cpp that were built (see cmake/TilthKernelLevels.cmake).
#include "residue_kernels.h"
#include "kernel_levels/kernel_levels.h"

namespace tilth::segmentation {

TILTH_KERNEL_LEVELS(ResidueKernels, kResidueKernels, residue_kernel_levels)

std::span<const ResidueKernels* const> available_residue_kernels() {
  return residue_kernel_levels().runnable();
}

}  // namespace tilth::segmentation
