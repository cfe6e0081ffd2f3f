// The estimators' per-row loop that gains from wide vectors: collecting a region's finite
// soil depths. soil_kernels.cpp is compiled once per instruction-set level
// (tilth/kernel_levels.h); the stages use the widest the CPU runs.
#pragma once

#include <span>

namespace tilth::estimation {

// Finite depths collected so far and their range (lowest > highest while there are none).
struct CollectedDepths {
  float* end;  // one past the last depth collected
  float lowest;
  float highest;
};

struct SoilKernels {
  // Appends the finite values of depth_mm[0, count) at `collected.end`, in order, and
  // widens the range to them. Writes up to kSlack floats past the last one appended.
  CollectedDepths (*collect_finite)(const float* depth_mm, int count, CollectedDepths collected);
  const char* level;  // "x86-64-v4", ...
};

// Room to leave after a collection's last slot for collect_finite's whole-vector stores.
inline constexpr int kSlack = 16;

// The levels this CPU runs, widest first: the stages use the first.
std::span<const SoilKernels* const> available_soil_kernels();

}  // namespace tilth::estimation
