// Two simulated cameras for the pairing tests: each captures at its own period and phase
// on the host's time line, stamps frames on its own clock (epoch and drift of its own),
// and delivers them late by a latency plus seeded random jitter. The frames of both
// come out merged in host arrival order, as the runtime hands them to a synchronizer.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <set>
#include <vector>

#include "pending_frame.h"

namespace tilth::pairing::testing {

struct CameraModel {
  std::int64_t period_ns = 33'333'333;
  std::int64_t phase_ns = 0;
  std::int64_t epoch_ns = 0;  // the device clock's reading at host time 0
  double drift_ppm = 0.0;     // device clock rate error
  std::int64_t latency_ns = 0;
  std::int64_t jitter_ns = 0;  // uniform in [0, jitter)
  std::uint64_t first_id = 1;
  std::set<std::uint64_t> dropped{};  // shot indices that never arrive
};

struct Shot {
  Side side;
  std::uint64_t index;      // the n-th capture of its camera
  std::int64_t capture_ns;  // true, on the host clock
  std::int64_t device_ns;   // the camera's timestamp
  std::int64_t host_ns;     // arrival
  std::uint64_t block_id;
};

inline std::vector<Shot> shoot(const CameraModel& depth, const CameraModel& color,
                               std::uint64_t count, std::uint32_t seed = 7) {
  std::mt19937 random(seed);
  std::vector<Shot> shots;
  for (Side side : {kDepth, kColor}) {
    const CameraModel& camera = side == kDepth ? depth : color;
    for (std::uint64_t n = 0; n < count; ++n) {
      const std::int64_t capture =
          camera.phase_ns + static_cast<std::int64_t>(n) * camera.period_ns;
      std::uniform_int_distribution<std::int64_t> jitter(
          0, std::max<std::int64_t>(camera.jitter_ns - 1, 0));
      const std::int64_t host = capture + camera.latency_ns + jitter(random);
      if (camera.dropped.count(n)) continue;
      const auto device =
          camera.epoch_ns +
          static_cast<std::int64_t>(static_cast<double>(capture) * (1.0 + camera.drift_ppm * 1e-6));
      shots.push_back({side, n, capture, device, host, camera.first_id + n});
    }
  }
  std::stable_sort(shots.begin(), shots.end(),
                   [](const Shot& a, const Shot& b) { return a.host_ns < b.host_ns; });
  return shots;
}

}  // namespace tilth::pairing::testing
