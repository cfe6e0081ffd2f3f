// The newest measurement a Modbus output has received, shared between the graph, which
// updates it from the sink's consume(), and the thread that talks Modbus, which turns it
// into register values at the moment it answers or writes (so age and staleness are
// exact then, whether or not measurements still arrive).
#pragma once

#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>

#include "register_map.h"
#include "tilth/messages/ground_distance.h"

namespace tilth::modbus {

class LatestMeasurement {
 public:
  using Clock = std::chrono::steady_clock;

  explicit LatestMeasurement(std::chrono::milliseconds stale_timeout)
      : stale_timeout_(stale_timeout) {}

  // `capture_age`: how old the frame already was when it arrived here. Ages are summed
  // exactly and cut to whole milliseconds once, when a register shows them.
  void update(std::uint64_t frame_id, const GroundDistance& distance, Clock::time_point arrived,
              Clock::duration capture_age);
  // A frame arrived without a measurement: a stage upstream failed on it, or the
  // cameras delivered no images for it.
  void update_missing(Clock::time_point arrived);
  // What the cameras said with the newest frame.
  void update_cameras(bool streaming);

  // Everything but the heartbeat, which belongs to the link that publishes the values.
  RegisterValues values_at(Clock::time_point now) const;

 private:
  struct Measurement {
    std::uint64_t frame_id = 0;
    bool valid = false;
    bool held = false;
    InvalidCause cause = InvalidCause::kNone;
    double distance_mm = 0.0;
    double soil_fraction = 0.0;
    double confidence = 0.0;
    Clock::time_point arrived;
    Clock::duration capture_age{0};
  };

  const std::chrono::milliseconds stale_timeout_;
  mutable std::mutex mutex_;
  std::optional<Measurement> measurement_;
  std::optional<Clock::time_point> last_frame_;  // with or without a measurement
  bool last_frame_missing_ = false;
  bool cameras_streaming_ = true;  // until a camera status says otherwise
};

}  // namespace tilth::modbus
