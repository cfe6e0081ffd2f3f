#include "framework/latency_histogram.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace tilth {

int LatencyHistogram::bucket_of(std::uint64_t value) {
  if (value < kSubBuckets) return static_cast<int>(value);
  const int exponent = std::bit_width(value) - 1;  // >= 4
  const int shift = exponent - 4;
  const int sub = static_cast<int>((value >> shift) & (kSubBuckets - 1));
  return std::min((exponent - 3) * kSubBuckets + sub, kBuckets - 1);
}

double LatencyHistogram::bucket_middle(int bucket) {
  if (bucket < kSubBuckets) return bucket;
  const int exponent = bucket / kSubBuckets + 3;
  const int sub = bucket % kSubBuckets;
  const double width = std::ldexp(1.0, exponent - 4);
  return std::ldexp(1.0, exponent) + (sub + 0.5) * width;
}

void LatencyHistogram::record(std::int64_t nanoseconds) {
  const std::uint64_t value = nanoseconds < 0 ? 0 : static_cast<std::uint64_t>(nanoseconds);
  std::lock_guard lock(mutex_);
  ++counts_[bucket_of(value)];
  ++count_;
  sum_ns_ += static_cast<double>(value);
  max_ns_ = std::max<std::int64_t>(max_ns_, static_cast<std::int64_t>(value));
}

double LatencyHistogram::percentile_locked(double fraction) const {
  if (count_ == 0) return 0.0;
  const auto rank = static_cast<std::uint64_t>(std::ceil(fraction * static_cast<double>(count_)));
  std::uint64_t seen = 0;
  for (int bucket = 0; bucket < kBuckets; ++bucket) {
    seen += counts_[bucket];
    if (seen >= std::max<std::uint64_t>(rank, 1)) {
      return std::min(bucket_middle(bucket), static_cast<double>(max_ns_));
    }
  }
  return static_cast<double>(max_ns_);
}

double LatencyHistogram::percentile_ns(double fraction) const {
  std::lock_guard lock(mutex_);
  return percentile_locked(fraction);
}

LatencySummary LatencyHistogram::summary() const {
  std::lock_guard lock(mutex_);
  constexpr double kMs = 1e-6;
  LatencySummary result;
  result.count = count_;
  if (count_ == 0) return result;
  result.mean_ms = sum_ns_ / static_cast<double>(count_) * kMs;
  result.p50_ms = percentile_locked(0.50) * kMs;
  result.p99_ms = percentile_locked(0.99) * kMs;
  result.max_ms = static_cast<double>(max_ns_) * kMs;
  return result;
}

}  // namespace tilth
