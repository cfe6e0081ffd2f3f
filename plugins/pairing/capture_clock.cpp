#include "capture_clock.h"

namespace tilth::pairing {

std::int64_t CaptureClock::capture_ns(std::int64_t device_ns, std::int64_t host_ns) {
  if (device_ns == 0) return host_ns;
  if (device_ns < last_device_ns_) lowest_.clear();  // the camera restarted its clock
  last_device_ns_ = device_ns;
  const std::int64_t offset = host_ns - device_ns;
  while (!lowest_.empty() && lowest_.back().offset_ns >= offset) lowest_.pop_back();
  lowest_.push_back({host_ns, offset});
  while (lowest_.front().host_ns < host_ns - window_ns_) lowest_.pop_front();
  return device_ns + lowest_.front().offset_ns;
}

}  // namespace tilth::pairing
