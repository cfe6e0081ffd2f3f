// The median of many values for a robust level or slope: the upper of the middle two for
// an even count, found by partial reordering in linear time.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace tilth::estimation {

// `values` must not be empty; their order is changed.
inline double upper_median(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace tilth::estimation
