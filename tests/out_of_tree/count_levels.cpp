// Prints, for each level this CPU runs, how many of 0, 1, ..., 1000 exceed 499.5: 501.
#include <cstdio>
#include <vector>

#include "count_kernels.h"

int main() {
  std::vector<float> values(1001);
  for (int i = 0; i < 1001; ++i) values[i] = static_cast<float>(i);
  for (const CountKernels* kernels : available_count_kernels()) {
    std::printf("%s: %d\n", kernels->level,
                kernels->count_above(values.data(), static_cast<int>(values.size()), 499.5f));
  }
}
