#include "tilth/kernel_levels.h"

namespace tilth {

bool cpu_runs_level(std::string_view level) {
  if (level == "baseline") return true;
#if defined(__x86_64__)
  // __builtin_cpu_supports takes string literals only.
  if (level == "x86-64-v2") return __builtin_cpu_supports("x86-64-v2") != 0;
  if (level == "x86-64-v3") return __builtin_cpu_supports("x86-64-v3") != 0;
  if (level == "x86-64-v4") return __builtin_cpu_supports("x86-64-v4") != 0;
#endif
  return false;
}

}  // namespace tilth
