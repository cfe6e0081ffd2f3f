// The levels of row_kernels.cpp that were built (see libs/kernel_levels/KernelLevels.cmake).
#include "kernel_levels/kernel_levels.h"
#include "row_kernels.h"

namespace tilth::registration {

TILTH_KERNEL_LEVELS(RowKernels, kRowKernels, levels)

std::vector<std::string> row_kernel_levels() { return levels().choices(); }

std::span<const RowKernels* const> available_row_kernels() { return levels().runnable(); }

const RowKernels& row_kernels(std::string_view level) { return levels().pick(level); }

}  // namespace tilth::registration
