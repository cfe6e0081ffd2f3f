// The levels of row_kernels.cpp that were built (TILTH_KERNEL_LEVELS_X86_64: the x86-64
// ones, see cmake/TilthKernelLevels.cmake).
#include "row_kernels.h"
#include "tilth/kernel_levels.h"

namespace tilth::registration {

namespace baseline {
extern const RowKernels kRowKernels;
}
#ifdef TILTH_KERNEL_LEVELS_X86_64
namespace x86_64_v2 {
extern const RowKernels kRowKernels;
}
namespace x86_64_v3 {
extern const RowKernels kRowKernels;
}
namespace x86_64_v4 {
extern const RowKernels kRowKernels;
}
#endif

namespace {

const KernelLevels<RowKernels>& levels() {
  static const KernelLevels<RowKernels> kLevels{
#ifdef TILTH_KERNEL_LEVELS_X86_64
      &x86_64_v4::kRowKernels, &x86_64_v3::kRowKernels, &x86_64_v2::kRowKernels,
#endif
      &baseline::kRowKernels};
  return kLevels;
}

}  // namespace

std::vector<std::string> row_kernel_levels() { return levels().choices(); }

std::span<const RowKernels* const> available_row_kernels() { return levels().runnable(); }

const RowKernels& row_kernels(std::string_view level) { return levels().pick(level); }

}  // namespace tilth::registration
