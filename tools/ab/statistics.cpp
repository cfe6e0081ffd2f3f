#include "statistics.h"

#include <algorithm>
#include <cmath>

#include "tilth/error.h"

namespace tilth::ab {
namespace {

// Continued fraction of the incomplete beta function (modified Lentz's method).
double beta_continued_fraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300;
  double c = 1.0;
  double d = 1.0 - (a + b) * x / (a + 1.0);
  if (std::abs(d) < kTiny) d = kTiny;
  d = 1.0 / d;
  double result = d;
  for (int m = 1; m <= 1000; ++m) {
    const double m2 = 2.0 * m;
    for (const double coefficient : {m * (b - m) * x / ((a + m2 - 1.0) * (a + m2)),
                                     -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1.0))}) {
      d = 1.0 + coefficient * d;
      if (std::abs(d) < kTiny) d = kTiny;
      c = 1.0 + coefficient / c;
      if (std::abs(c) < kTiny) c = kTiny;
      d = 1.0 / d;
      result *= d * c;
    }
    if (std::abs(d * c - 1.0) < 1e-15) break;
  }
  return result;
}

double regularized_incomplete_beta(double a, double b, double x) {
  if (x <= 0.0) return 0.0;
  if (x >= 1.0) return 1.0;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  if (x < (a + 1.0) / (a + b + 2.0)) return front * beta_continued_fraction(a, b, x) / a;
  return 1.0 - front * beta_continued_fraction(b, a, 1.0 - x) / b;
}

double student_t_cdf(double t, double dof) {
  const double tail = 0.5 * regularized_incomplete_beta(dof / 2.0, 0.5, dof / (dof + t * t));
  return t >= 0.0 ? 1.0 - tail : tail;
}

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
  if (p < 0.5) return -student_t_quantile(1.0 - p, dof);
  double low = 0.0, high = 1.0;
  while (student_t_cdf(high, dof) < p) high *= 2.0;
  for (int i = 0; i < 200 && high - low > 1e-13 * high; ++i) {
    const double middle = 0.5 * (low + high);
    (student_t_cdf(middle, dof) < p ? low : high) = middle;
  }
  return 0.5 * (low + high);
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
