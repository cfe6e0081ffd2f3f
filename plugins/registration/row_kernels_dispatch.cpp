// The levels of row_kernels.cpp that were built (TILTH_KERNEL_LEVELS_X86_64: the x86-64
// ones, see CMakeLists.txt) and that this CPU runs.
#include <string>
#include <vector>

#include "row_kernels.h"
#include "tilth/error.h"

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

struct Level {
  const RowKernels* kernels;
  bool runs;
};

std::vector<Level> built_levels() {
  return {
#ifdef TILTH_KERNEL_LEVELS_X86_64
      {&x86_64_v4::kRowKernels, __builtin_cpu_supports("x86-64-v4") != 0},
      {&x86_64_v3::kRowKernels, __builtin_cpu_supports("x86-64-v3") != 0},
      {&x86_64_v2::kRowKernels, __builtin_cpu_supports("x86-64-v2") != 0},
#endif
      {&baseline::kRowKernels, true}};
}

std::vector<const RowKernels*> runnable_row_kernels() {
  std::vector<const RowKernels*> levels;
  for (const Level& level : built_levels()) {
    if (level.runs) levels.push_back(level.kernels);
  }
  return levels;
}

}  // namespace

std::vector<std::string> row_kernel_levels() {
  std::vector<std::string> names = {"auto"};
  for (const Level& level : built_levels()) names.emplace_back(level.kernels->level);
  return names;
}

std::span<const RowKernels* const> available_row_kernels() {
  static const std::vector<const RowKernels*> kLevels = runnable_row_kernels();
  return kLevels;
}

const RowKernels& row_kernels(std::string_view level) {
  const auto levels = available_row_kernels();
  if (level == "auto") return *levels.front();
  std::string runnable;
  for (const RowKernels* kernels : levels) {
    if (kernels->level == level) return *kernels;
    runnable += std::string(runnable.empty() ? "" : ", ") + kernels->level;
  }
  throw Error("this CPU does not run instruction set " + std::string(level) + "; it runs " +
              runnable);
}

}  // namespace tilth::registration
