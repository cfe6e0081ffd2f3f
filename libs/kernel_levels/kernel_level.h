// What a kernel source compiled once per instruction-set level (tilth_add_kernel_levels,
// kernel_levels.h) sees of the level it is compiled for: the 32-bit lanes of one
// vector register. A constant, not a function, so that each compilation has its own.
#pragma once

#ifndef TILTH_KERNEL_LEVEL
#error "compile with TILTH_KERNEL_LEVEL (the namespace) and TILTH_KERNEL_LEVEL_NAME"
#endif

namespace tilth {

#if defined(__AVX2__)
constexpr int kKernelLanes = 8;
#else
constexpr int kKernelLanes = 4;  // SSE2, NEON
#endif

}  // namespace tilth
