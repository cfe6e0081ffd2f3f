#include "statistics.h"

#include <algorithm>
#include <cmath>

#include <boost/math/distributions/students_t.hpp>

#include "tilth/error.h"

namespace tilth::ab {
namespace {

std::optional<double> ratio(std::int64_t numerator, std::int64_t denominator) {
  if (denominator == 0) return std::nullopt;
  return static_cast<double>(numerator) / static_cast<double>(denominator);
}

}  // namespace

ErrorStats error_stats(const std::vector<double>& errors_mm) {
  ErrorStats stats;
  stats.count = errors_mm.size();
  if (errors_mm.empty()) return stats;
  double sum = 0.0, sum_abs = 0.0, sum_squares = 0.0;
  for (const double error : errors_mm) {
    sum += error;
    sum_abs += std::abs(error);
    sum_squares += error * error;
    stats.max_abs_mm = std::max(stats.max_abs_mm, std::abs(error));
  }
  const double n = static_cast<double>(errors_mm.size());
  stats.mean_mm = sum / n;
  stats.mean_abs_mm = sum_abs / n;
  stats.rms_mm = std::sqrt(sum_squares / n);
  if (errors_mm.size() < 2) return stats;
  double squared_deviations = 0.0;
  for (const double error : errors_mm) {
    squared_deviations += (error - stats.mean_mm) * (error - stats.mean_mm);
  }
  stats.std_mm = std::sqrt(squared_deviations / (n - 1.0));
  const double half_width = student_t_quantile(0.975, n - 1.0) * *stats.std_mm / std::sqrt(n);
  stats.ci95_low_mm = stats.mean_mm - half_width;
  stats.ci95_high_mm = stats.mean_mm + half_width;
  return stats;
}

double student_t_quantile(double p, double dof) {
  if (!(p > 0.0 && p < 1.0) || !(dof > 0.0)) {
    throw Error("student_t_quantile: expected 0 < p < 1 and dof > 0, got p " + std::to_string(p) +
                ", dof " + std::to_string(dof));
  }
  return boost::math::quantile(boost::math::students_t(dof), p);
}

MaskCounts& MaskCounts::operator+=(const MaskCounts& other) {
  tp += other.tp;
  fp += other.fp;
  fn += other.fn;
  tn += other.tn;
  unknown += other.unknown;
  return *this;
}

std::optional<double> MaskCounts::iou() const { return ratio(tp, tp + fp + fn); }
std::optional<double> MaskCounts::precision() const { return ratio(tp, tp + fp); }
std::optional<double> MaskCounts::recall() const { return ratio(tp, tp + fn); }

HistogramBins histogram_bins(const std::vector<double>& all_errors_mm, std::size_t max_bins) {
  HistogramBins bins;
  if (all_errors_mm.empty() || max_bins == 0) return bins;
  const auto [low, high] = std::minmax_element(all_errors_mm.begin(), all_errors_mm.end());
  const double span = std::max(*high - *low, 1e-3);
  const double raw_width = span / static_cast<double>(max_bins);
  double decade = std::pow(10.0, std::floor(std::log10(raw_width)));
  bins.width_mm = decade * 10.0;
  for (const double step : {1.0, 2.0, 5.0}) {
    if (step * decade >= raw_width) {
      bins.width_mm = step * decade;
      break;
    }
  }
  bins.first_edge_mm = std::floor(*low / bins.width_mm) * bins.width_mm;
  bins.count =
      static_cast<std::size_t>(std::floor((*high - bins.first_edge_mm) / bins.width_mm)) + 1;
  return bins;
}

std::vector<std::size_t> histogram(const HistogramBins& bins,
                                   const std::vector<double>& errors_mm) {
  std::vector<std::size_t> counts(bins.count, 0);
  if (bins.count == 0) return counts;
  for (const double error : errors_mm) {
    const double position = std::floor((error - bins.first_edge_mm) / bins.width_mm);
    const auto index =
        static_cast<std::size_t>(std::clamp(position, 0.0, static_cast<double>(bins.count - 1)));
    ++counts[index];
  }
  return counts;
}

}  // namespace tilth::ab
