// An example of kernels compiled once per instruction-set level out of tree
// (tilth_add_kernel_levels): counting the values above a threshold.
#pragma once

#include <span>

struct CountKernels {
  int (*count_above)(const float* values, int count, float threshold);
  const char* level;
};

// The levels this CPU runs, widest first.
std::span<const CountKernels* const> available_count_kernels();
