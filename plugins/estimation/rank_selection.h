// The k-th smallest of many floats, and the sum of the k smallest, in linear time and
// exactly: a histogram of the values narrows a rank down to one bin, and only that bin's
// few values are selected. For the soil depths of a frame, ranks cost a few passes over
// the values instead of a selection that reorders all of them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace tilth::estimation {

class RankSelection {
 public:
  // Prepares for ranks of `values` (finite), which must outlive the queries. Keeps its
  // buffers from one call to the next.
  void index(std::span<const float> values);
  // The same when a range that holds every value is known already: one pass fewer.
  void index(std::span<const float> values, float lowest, float highest);

  // The k-th smallest value, k < size.
  float at_rank(std::size_t k);
  // The middle value, or the mean of the middle two for an even size; size > 0.
  double median();
  // The sum of the k smallest values, k <= size.
  double sum_of_smallest(std::size_t k);

 private:
  std::size_t bin_of_rank(std::size_t k) const;
  // Gathers the values in bins first..last into candidates_.
  void gather_bins(std::size_t first, std::size_t last);

  std::span<const float> values_;
  std::vector<std::uint16_t> bin_of_value_;
  std::vector<std::uint32_t> counts_;     // per bin, in two interleaved histograms
  std::vector<std::uint32_t> below_bin_;  // how many values lie in the bins before each
  std::vector<float> candidates_;
};

}  // namespace tilth::estimation
