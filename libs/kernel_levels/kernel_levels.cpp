#include "kernel_levels/kernel_levels.h"

namespace tilth {

bool cpu_runs_level(std::string_view level) {
  if (level == "baseline") return true;
#if defined(__x86_64__) && defined(__clang__)
  // Clang (Debian's 14, which builds the fuzz targets) knows no level names, only
  // features; it leaves out f16c, lzcnt and movbe (on every CPU with AVX2, BMI2 and FMA).
  // Feature names must be literals.
  if (level == "x86-64-v3") {
    return __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt") &&
           __builtin_cpu_supports("avx2") && __builtin_cpu_supports("bmi2") &&
           __builtin_cpu_supports("fma");
  }
#elif defined(__x86_64__)
  // __builtin_cpu_supports takes string literals only.
  if (level == "x86-64-v3") return __builtin_cpu_supports("x86-64-v3") != 0;
#endif
  return false;
}

}  // namespace tilth
