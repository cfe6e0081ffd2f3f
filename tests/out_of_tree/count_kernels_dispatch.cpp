// The levels of count_kernels.cpp that were built.
#include "count_kernels.h"
#include "tilth/kernel_levels.h"

TILTH_KERNEL_LEVELS(CountKernels, kCountKernels, count_kernel_levels)

std::span<const CountKernels* const> available_count_kernels() {
  return count_kernel_levels().runnable();
}
