#include "simulated_pairs.h"

#include <nlohmann/json.hpp>

#include "source_tree.h"
#include "tilth/plugin.h"

namespace tilth::testing {

std::vector<SimulatedPair> render_pairs(StageRegistry& registry, const std::string& preset,
                                        int count) {
  nlohmann::json params = {{"calibration", paper_rig_path().string()}, {"preset", preset}};
  for (const auto& spec : registry.find("synthetic.scene")->descriptor.params) {
    if (!params.contains(spec.name)) params[spec.name] = spec.default_value;
  }
  StageInstance scene = registry.create("synthetic.scene",
                                        StageContext{"scene", Params(params), Logger("scene"), {}});
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
