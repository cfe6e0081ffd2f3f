// The checks of `tilth doctor` on the GigE Vision cameras: found, on a subnet of this host
// with no address conflict, packets that fit the interface's MTU, a few seconds of
// streaming without lost packets, and clocks that advance at the same rate.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "finding.h"

namespace tilth::doctor {

struct CameraChecks {
  std::vector<Finding> findings;
  std::uint64_t largest_frame_bytes = 0;  // for the receive-buffer check
};

// `cameras`: names as a stage's `camera` parameter takes them (address, serial, device
// id); empty checks every camera that answers a discovery.
CameraChecks check_cameras(const std::vector<std::string>& cameras,
                           std::chrono::milliseconds streaming);

}  // namespace tilth::doctor
