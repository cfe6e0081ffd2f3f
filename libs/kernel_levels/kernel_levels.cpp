#include "kernel_levels/kernel_levels.h"

namespace tilth {

bool cpu_runs_level(std::string_view level) {
  if (level == "baseline") return true;
#if defined(__x86_64__) && defined(__clang__)
  // Clang (Debian's 14, which builds the fuzz targets) knows no level names, only
  // features; it leaves out cx16 and lahf (on every CPU with SSE4.2) and f16c, lzcnt and
  // movbe (on every CPU with AVX2, BMI2 and FMA). Feature names must be literals.
  const bool v2 = __builtin_cpu_supports("sse3") && __builtin_cpu_supports("ssse3") &&
                  __builtin_cpu_supports("sse4.1") && __builtin_cpu_supports("sse4.2") &&
                  __builtin_cpu_supports("popcnt");
  const bool v3 = v2 && __builtin_cpu_supports("avx") && __builtin_cpu_supports("avx2") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                  __builtin_cpu_supports("fma");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                  __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512vl");
  if (level == "x86-64-v2") return v2;
  if (level == "x86-64-v3") return v3;
  if (level == "x86-64-v4") return v4;
#elif defined(__x86_64__)
  // __builtin_cpu_supports takes string literals only.
  if (level == "x86-64-v2") return __builtin_cpu_supports("x86-64-v2") != 0;
  if (level == "x86-64-v3") return __builtin_cpu_supports("x86-64-v3") != 0;
  if (level == "x86-64-v4") return __builtin_cpu_supports("x86-64-v4") != 0;
#endif
  return false;
}

}  // namespace tilth
