// Puts one camera's capture times on the host clock. A camera stamps frames on its own
// clock (an unknown epoch, drifting against the host's); the host stamps them when they
// arrive, late by a transfer time that varies. The lower envelope of (host - device) over
// a sliding window is the camera-to-host offset without that jitter: it follows drift
// with an error of at most drift x window, and restarts when the camera's clock does.
#pragma once

#include <cstdint>
#include <deque>

namespace tilth::pairing {

class CaptureClock {
 public:
  explicit CaptureClock(std::int64_t window_ns) : window_ns_(window_ns) {}

  // The capture time of a frame on the host clock. Without a device timestamp (0), the
  // host's receive time is all there is.
  std::int64_t capture_ns(std::int64_t device_ns, std::int64_t host_ns);

 private:
  struct Sample {
    std::int64_t host_ns;
    std::int64_t offset_ns;  // host - device
  };

  const std::int64_t window_ns_;
  std::deque<Sample> lowest_;  // offsets increasing from front to back, within the window
  std::int64_t last_device_ns_ = 0;
};

}  // namespace tilth::pairing
