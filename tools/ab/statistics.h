// The figures of a comparison: distance-error statistics with the 95 % confidence
// interval of the mean (Student's t), and mask agreement counted over pixels.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace tilth::ab {

struct ErrorStats {
  std::size_t count = 0;
  double mean_mm = 0.0;  // signed: measured minus true
  double mean_abs_mm = 0.0;
  double max_abs_mm = 0.0;
  double rms_mm = 0.0;
  std::optional<double> std_mm;  // sample standard deviation (n - 1); needs 2 values
  // mean -/+ t(0.975, n-1) * std / sqrt(n): where the mean error lies with 95 %
  // confidence, as in the paper's Table 2. Needs 2 values.
  std::optional<double> ci95_low_mm;
  std::optional<double> ci95_high_mm;
};

// Sums in the given order, so the same errors in the same order give the same bits.
ErrorStats error_stats(const std::vector<double>& errors_mm);

// The p-quantile of Student's t distribution with `dof` degrees of freedom (dof > 0,
// 0 < p < 1), from the regularized incomplete beta function, to ~1e-12.
double student_t_quantile(double p, double dof);

// Residue is the positive class; pixels whose truth is unknown are not counted.
struct MaskCounts {
  std::int64_t tp = 0;       // residue called residue
  std::int64_t fp = 0;       // soil called residue
  std::int64_t fn = 0;       // residue called soil or unknown: it reaches the soil depth
  std::int64_t tn = 0;       // soil called soil or unknown
  std::int64_t unknown = 0;  // called unknown (among fn + tn)

  MaskCounts& operator+=(const MaskCounts& other);
  // Each is empty when its denominator is 0.
  std::optional<double> iou() const;
  std::optional<double> precision() const;
  std::optional<double> recall() const;
};

// Equal-width bins over the errors of every variant, so histograms compare directly:
// the width is 1, 2 or 5 times a power of ten giving at most `max_bins` bins.
struct HistogramBins {
  double first_edge_mm = 0.0;
  double width_mm = 1.0;
  std::size_t count = 0;
};
HistogramBins histogram_bins(const std::vector<double>& all_errors_mm, std::size_t max_bins);
std::vector<std::size_t> histogram(const HistogramBins& bins, const std::vector<double>& errors_mm);

}  // namespace tilth::ab
