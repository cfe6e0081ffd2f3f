#include "registered_frames.h"

#include <algorithm>
#include <vector>

#include "stage_in_process.h"
#include "tilth/error.h"

namespace tilth::train_segmenter {
namespace {

using tools::make_stage;
using tools::stage_as;

std::size_t port_index(const std::vector<PortSpec>& ports, const std::string& name,
                       const std::string& type) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (ports[i].name == name) return i;
  }
  throw Error(type + " has no port '" + name + "'");
}

}  // namespace

class RegisteredFrames::Chain {
 public:
  Chain(const StageRegistry& registry, const std::string& source_type,
        const nlohmann::json& source_params, const std::filesystem::path& calibration)
      : source_(make_stage(registry, source_type, source_params)),
        projection_(
            make_stage(registry, "depth.projection", {{"calibration", calibration.string()}})),
        registration_(make_stage(registry, "registration.projective",
                                 {{"calibration", calibration.string()}})),
        source_outputs_(registry.find(source_type)->descriptor.outputs.size()),
        raw_port_(port_index(registry.find(source_type)->descriptor.outputs, "raw", source_type)),
        color_port_(
            port_index(registry.find(source_type)->descriptor.outputs, "color", source_type)),
        truth_port_(
            port_index(registry.find(source_type)->descriptor.outputs, "truth", source_type)),
        source_type_(source_type) {}

  std::optional<RegisteredFrame> next() {
    std::fill(source_outputs_.begin(), source_outputs_.end(), Packet{});
    Frame produced(FrameInfo{}, {}, source_outputs_);
    if (!stage_as<Source>(source_, source_type_).produce(produced)) return std::nullopt;
    const FrameInfo info = produced.info();
    auto outputs = [&](std::size_t port) { return Packet(info, source_outputs_[port].message()); };

    std::vector<Packet> depth(1);
    const std::vector<Packet> raw{outputs(raw_port_)};
    Frame projecting(info, raw, depth);
    stage_as<Transform>(projection_, "depth.projection").process(projecting);

    std::vector<Packet> color(1);
    const std::vector<Packet> registering{depth[0], outputs(color_port_)};
    Frame registration(info, registering, color);
    stage_as<Transform>(registration_, "registration.projective").process(registration);

    RegisteredFrame frame;
    frame.frame_id = info.frame_id;
    frame.color = color[0].share<RegisteredColor>();
    frame.depth = depth[0].share<DepthImage>();
    frame.truth = outputs(truth_port_).share<GroundTruth>();
    return frame;
  }

 private:
  StageInstance source_;
  StageInstance projection_;
  StageInstance registration_;
  std::vector<Packet> source_outputs_;
  const std::size_t raw_port_;
  const std::size_t color_port_;
  const std::size_t truth_port_;
  const std::string source_type_;
};

RegisteredFrames::RegisteredFrames(const StageRegistry& registry, const std::string& source_type,
                                   const nlohmann::json& source_params,
                                   const std::filesystem::path& calibration)
    : chain_(std::make_unique<Chain>(registry, source_type, source_params, calibration)) {}

RegisteredFrames::~RegisteredFrames() = default;

std::optional<RegisteredFrame> RegisteredFrames::next() { return chain_->next(); }

}  // namespace tilth::train_segmenter
