// Latency distribution in fixed memory: log-linear buckets (16 per power of two, so a
// percentile is within ~4% of the true value), exact count, mean and max.
#pragma once

#include <array>
#include <cstdint>
#include <mutex>

#include "tilth/messages/pipeline_metrics.h"

namespace tilth {

class LatencyHistogram {
 public:
  void record(std::int64_t nanoseconds);
  LatencySummary summary() const;
  // The value below which `fraction` of the samples lie, in nanoseconds.
  double percentile_ns(double fraction) const;

 private:
  static constexpr int kSubBuckets = 16;
  static constexpr int kBuckets = 64 * kSubBuckets;
  static int bucket_of(std::uint64_t value);
  static double bucket_middle(int bucket);
  double percentile_locked(double fraction) const;

  mutable std::mutex mutex_;
  std::array<std::uint64_t, kBuckets> counts_{};
  std::uint64_t count_ = 0;
  double sum_ns_ = 0.0;
  std::int64_t max_ns_ = 0;
};

}  // namespace tilth
