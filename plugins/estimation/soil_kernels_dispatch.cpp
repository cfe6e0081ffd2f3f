// The levels of soil_kernels.cpp that were built (see cmake/TilthKernelLevels.cmake).
#include "soil_kernels.h"
#include "tilth/kernel_levels.h"

namespace tilth::estimation {

TILTH_KERNEL_LEVELS(SoilKernels, kSoilKernels, soil_kernel_levels)

std::span<const SoilKernels* const> available_soil_kernels() {
  return soil_kernel_levels().runnable();
}

}  // namespace tilth::estimation
