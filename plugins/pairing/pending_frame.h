// A camera frame waiting for its partner from the other camera, and a matched pair.
#pragma once

#include <cstdint>

#include "tilth/packet.h"

namespace tilth::pairing {

enum Side : int { kDepth = 0, kColor = 1 };

struct PendingFrame {
  std::int64_t capture_ns = 0;  // on the host clock (CaptureClock)
  FrameInfo info;               // as the camera's source stamped it
  Packet image;
};

struct MatchedPair {
  PendingFrame depth;
  PendingFrame color;
};

}  // namespace tilth::pairing
