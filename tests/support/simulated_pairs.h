// Frame pairs rendered by synthetic.scene, each with its own noise: camera-like images
// for benchmarks, without cameras.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "framework/stage_registry.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/raw_tof_frame.h"

namespace tilth::testing {

struct SimulatedPair {
  std::shared_ptr<const RawTofFrame> raw;
  std::shared_ptr<const ColorImage> color;
};

// `count` pairs of the simulator's `preset` on the paper's rig; `registry` holds the
// synthetic plugin.
std::vector<SimulatedPair> render_pairs(StageRegistry& registry, const std::string& preset,
                                        int count);

}  // namespace tilth::testing
