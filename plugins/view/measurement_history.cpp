#include "measurement_history.h"

#include <vector>

namespace tilth::view {

void MeasurementHistory::add(std::uint64_t frame_id, double t, const GroundDistance& distance) {
  const double span_s = std::chrono::duration<double>(span_).count();
  std::lock_guard lock(mutex_);
  samples_.push_back({++last_, frame_id, t, distance.distance_mm, distance.valid, distance.held,
                      distance.cause, distance.soil_fraction});
  while (!samples_.empty() && samples_.front().t < t - span_s) samples_.pop_front();
}

nlohmann::json MeasurementHistory::since(std::uint64_t after) const {
  // Copied under the lock, written out after it: add() never waits for the JSON.
  std::vector<Sample> copied;
  std::uint64_t last = 0;
  {
    std::lock_guard lock(mutex_);
    last = last_;
    for (const Sample& sample : samples_) {
      if (sample.number > after) copied.push_back(sample);
    }
  }
  nlohmann::json samples = nlohmann::json::array();
  for (const Sample& sample : copied) {
    samples.push_back({{"n", sample.number},
                       {"frame", sample.frame_id},
                       {"t", sample.t},
                       {"mm", sample.valid ? nlohmann::json(sample.distance_mm) : nullptr},
                       {"valid", sample.valid},
                       {"held", sample.held},
                       {"cause", to_string(sample.cause)},
                       {"soil", sample.soil_fraction}});
  }
  return {{"last", last}, {"samples", std::move(samples)}};
}

std::uint64_t MeasurementHistory::last() const {
  std::lock_guard lock(mutex_);
  return last_;
}

}  // namespace tilth::view
