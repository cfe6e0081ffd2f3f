// The measurements of the last minute or so, for the live view's plot: one sample per
// frame that reached the view, kept for a time span and sent to viewers as JSON.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>

#include <nlohmann/json.hpp>

#include "tilth/messages/ground_distance.h"

namespace tilth::view {

class MeasurementHistory {
 public:
  explicit MeasurementHistory(std::chrono::milliseconds span) : span_(span) {}

  // The measurement of frame `frame_id`, reaching the view at `t` (seconds on a clock
  // that never goes back).
  void add(std::uint64_t frame_id, double t, const GroundDistance& distance);
  // The samples added after the one numbered `after` (all kept when 0), as
  // {"last": N, "samples": [{"n", "frame", "t", "mm", "valid", "held", "cause", "soil"}]}.
  nlohmann::json since(std::uint64_t after) const;
  std::uint64_t last() const;

 private:
  struct Sample {
    std::uint64_t number;
    std::uint64_t frame_id;
    double t;
    double distance_mm;
    bool valid;
    bool held;
    InvalidCause cause;
    double soil_fraction;
  };

  const std::chrono::milliseconds span_;
  mutable std::mutex mutex_;
  std::deque<Sample> samples_;
  std::uint64_t last_ = 0;
};

}  // namespace tilth::view
