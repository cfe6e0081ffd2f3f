// The outputs of one node for one frame: what flows between nodes of a running graph.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "tilth/packet.h"

namespace tilth {

struct Bundle {
  std::size_t node = 0;
  FrameInfo info;
  std::vector<Packet> outputs;  // one per output port; empty where nothing was produced
};

using BundlePtr = std::shared_ptr<const Bundle>;

}  // namespace tilth
