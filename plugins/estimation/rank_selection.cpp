#include "rank_selection.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace tilth::estimation {
namespace {

// Fine enough that a bin holds a small share of a frame's soil depths, small enough that
// the counts stay in the L1 cache.
constexpr std::size_t kBins = 4096;

std::pair<float, float> range(std::span<const float> values) {
  float lowest = values[0];
  float highest = values[0];
  for (const float value : values) {
    lowest = std::min(lowest, value);
    highest = std::max(highest, value);
  }
  return {lowest, highest};
}

}  // namespace

void RankSelection::index(std::span<const float> values) {
  if (values.empty()) {
    index(values, 0.0f, 0.0f);
    return;
  }
  const auto [lowest, highest] = range(values);
  index(values, lowest, highest);
}

void RankSelection::index(std::span<const float> values, float lowest, float highest) {
  values_ = values;
  below_bin_.assign(kBins + 1, 0);
  if (values.empty()) return;
  const std::size_t count = values.size();
  bin_of_value_.resize(count);
  counts_.assign(2 * kBins, 0);
  // Each step (subtract, scale, clamp, truncate) is monotone, so a larger value never
  // lands in an earlier bin: the values of rank k lie in the bin where the counts say.
  // Float overflow only makes a difference infinite, which the clamp takes to the last bin.
  const auto scale = static_cast<float>(
      highest > lowest ? kBins / (static_cast<double>(highest) - static_cast<double>(lowest))
                       : 0.0);
  const auto last_bin = static_cast<float>(kBins - 1);
  const auto bin_of = [&](float value) {
    return static_cast<std::uint16_t>(std::min((value - lowest) * scale, last_bin));
  };
  std::uint16_t* const bins = bin_of_value_.data();
  for (std::size_t i = 0; i < count; ++i) bins[i] = bin_of(values[i]);
  // Two histograms, the values in turn, so that a run of values in one bin does not wait
  // for each increment before the next. Through local pointers, which no store changes.
  std::uint32_t* const counts = counts_.data();
  std::uint32_t* const other_counts = counts + kBins;
  std::size_t i = 0;
  for (; i + 2 <= count; i += 2) {
    ++counts[bins[i]];
    ++other_counts[bins[i + 1]];
  }
  if (i < count) ++counts[bins[i]];
  for (std::size_t bin = 0; bin < kBins; ++bin) {
    below_bin_[bin + 1] = below_bin_[bin] + counts[bin] + other_counts[bin];
  }
}

std::size_t RankSelection::bin_of_rank(std::size_t k) const {
  return static_cast<std::size_t>(std::upper_bound(below_bin_.begin(), below_bin_.end(), k) -
                                  below_bin_.begin() - 1);
}

void RankSelection::gather_bins(std::size_t first, std::size_t last) {
  // Groups of eight values are tested at once; only groups with one in the bins are
  // gathered, without a branch per value: each is stored, and the count moves on past
  // those in the bins. One slot more for the last store.
  candidates_.resize(below_bin_[last + 1] - below_bin_[first] + 1);
  const std::uint16_t* bins = bin_of_value_.data();
  const auto lowest = static_cast<std::uint16_t>(first);
  const auto span = static_cast<std::uint16_t>(last - first);
  const auto in_bins = [&](std::size_t i) {
    return static_cast<std::uint16_t>(bins[i] - lowest) <= span;
  };
  std::size_t count = 0;
  const auto gather = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      candidates_[count] = values_[i];
      count += in_bins(i) ? 1 : 0;
    }
  };
  constexpr std::size_t kGroup = 8;
  std::size_t i = 0;
  for (; i + kGroup <= values_.size(); i += kGroup) {
    bool any = false;
    for (std::size_t j = i; j < i + kGroup; ++j) any |= in_bins(j);
    if (any) gather(i, i + kGroup);
  }
  gather(i, values_.size());
}

float RankSelection::at_rank(std::size_t k) {
  const std::size_t bin = bin_of_rank(k);
  gather_bins(bin, bin);
  const auto end = candidates_.end() - 1;
  const auto kth = candidates_.begin() + static_cast<std::ptrdiff_t>(k - below_bin_[bin]);
  std::nth_element(candidates_.begin(), kth, end);
  return *kth;
}

double RankSelection::median() {
  const std::size_t upper = values_.size() / 2;
  if (values_.size() % 2 == 1) return at_rank(upper);
  // Both middle values from one gathering: the lower is the largest of those the
  // selection of the upper puts before it.
  const std::size_t first = bin_of_rank(upper - 1);
  gather_bins(first, bin_of_rank(upper));
  const auto end = candidates_.end() - 1;
  const auto kth = candidates_.begin() + static_cast<std::ptrdiff_t>(upper - below_bin_[first]);
  std::nth_element(candidates_.begin(), kth, end);
  const float lower = *std::max_element(candidates_.begin(), kth);
  return 0.5 * (static_cast<double>(lower) + static_cast<double>(*kth));
}

double RankSelection::sum_of_smallest(std::size_t k) {
  if (k == 0) return 0.0;
  const std::size_t bin = bin_of_rank(k - 1);
  gather_bins(bin, bin);
  double sum = 0.0;
  for (std::size_t i = 0; i < values_.size(); ++i) {
    sum += bin_of_value_[i] < bin ? static_cast<double>(values_[i]) : 0.0;
  }
  const auto end = candidates_.end() - 1;
  const auto last = candidates_.begin() + static_cast<std::ptrdiff_t>(k - 1 - below_bin_[bin]);
  std::nth_element(candidates_.begin(), last, end);
  return std::accumulate(candidates_.begin(), last + 1, sum);
}

}  // namespace tilth::estimation
