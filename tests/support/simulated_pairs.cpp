#include "simulated_pairs.h"

#include <nlohmann/json.hpp>

#include "source_tree.h"
#include "tilth/plugin.h"
#include "tilth/stage_params.h"

namespace tilth::testing {

std::vector<SimulatedPair> render_pairs(StageRegistry& registry, const std::string& preset,
                                        int count) {
  const Params params =
      stage_params(registry.find("synthetic.scene")->descriptor,
                   {{"calibration", paper_rig_path().string()}, {"preset", preset}});
  StageInstance scene =
      registry.create("synthetic.scene", StageContext{"scene", params, Logger("scene"), {}});
  std::vector<SimulatedPair> rendered;
  for (int i = 0; i < count; ++i) {
    std::vector<Packet> outputs(3);
    Frame frame(FrameInfo{}, {}, outputs);
    dynamic_cast<Source&>(*scene.stage).produce(frame);
    rendered.push_back({outputs[0].share<RawTofFrame>(), outputs[1].share<ColorImage>()});
  }
  return rendered;
}

}  // namespace tilth::testing
