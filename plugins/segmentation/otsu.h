// Otsu's threshold on a histogram: the split into a lower and an upper class that
// maximises the variance between them, with the class means a caller needs to judge
// whether there are two classes at all.
#pragma once

#include <optional>
#include <span>

namespace tilth::segmentation {

struct OtsuSplit {
  int threshold_bin = 0;  // the first bin of the upper class
  double lower_mean = 0;  // mean bin index of each class
  double upper_mean = 0;
  double upper_fraction = 0;  // of the histogram's total count
};

// Empty when fewer than two bins are occupied (nothing to split). Where several
// thresholds give the same, largest between-class variance (empty bins between two
// modes), the middle one is taken: halfway between the classes.
std::optional<OtsuSplit> otsu_split(std::span<const double> histogram);

}  // namespace tilth::segmentation
