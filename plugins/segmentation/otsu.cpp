#include "otsu.h"

#include <vector>

namespace tilth::segmentation {

std::optional<OtsuSplit> otsu_split(std::span<const double> histogram) {
  const int bins = static_cast<int>(histogram.size());
  double total = 0;
  double weighted = 0;
  int occupied = 0;
  for (int i = 0; i < bins; ++i) {
    total += histogram[i];
    weighted += i * histogram[i];
    occupied += histogram[i] > 0 ? 1 : 0;
  }
  if (occupied < 2) return std::nullopt;

  // Between-class variance (up to the constant factor 1 / total^2) of the split before
  // each bin t = 1 .. bins-1: (mean_total * w0 - m0)^2 / (w0 * w1), with w0, m0 the
  // lower class's count and first moment.
  std::vector<double> between(bins, -1.0);
  double w0 = 0;
  double m0 = 0;
  double best = -1.0;
  for (int t = 1; t < bins; ++t) {
    w0 += histogram[t - 1];
    m0 += (t - 1) * histogram[t - 1];
    const double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double d = weighted * w0 / total - m0;
    between[t] = d * d / (w0 * w1);
    if (between[t] > best) best = between[t];
  }
  // The first plateau of maximal thresholds; relative tolerance for rounding.
  int first = 1;
  while (between[first] < best * (1 - 1e-12)) ++first;
  int last = first;
  while (last + 1 < bins && between[last + 1] >= best * (1 - 1e-12)) ++last;

  OtsuSplit split;
  split.threshold_bin = (first + last + 1) / 2;
  double lower_count = 0;
  double lower_moment = 0;
  for (int i = 0; i < split.threshold_bin; ++i) {
    lower_count += histogram[i];
    lower_moment += i * histogram[i];
  }
  split.lower_mean = lower_moment / lower_count;
  split.upper_mean = (weighted - lower_moment) / (total - lower_count);
  split.upper_fraction = (total - lower_count) / total;
  return split;
}

}  // namespace tilth::segmentation
