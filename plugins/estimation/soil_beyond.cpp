#include "soil_beyond.h"

#include <algorithm>
#include <cstddef>
#include <numeric>

namespace tilth::estimation {

double SoilBeyond::least_share() const {
  const double total = std::accumulate(weight_.begin(), weight_.end(), 0.0);
  if (total <= 0) return 0.0;
  double least = 1.0;
  for (std::size_t quadrant = 0; quadrant < weight_.size(); ++quadrant) {
    if (weight_[quadrant] < kMinQuadrantShare * total) return 0.0;
    least = std::min(least, beyond_[quadrant] / weight_[quadrant]);
  }
  return least;
}

}  // namespace tilth::estimation
