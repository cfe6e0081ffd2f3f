#include "registered_frames.h"

#include <algorithm>
#include <vector>

#include "tilth/error.h"

namespace tilth::train_segmenter {
namespace {

// A stage made as the graph loader would make it: every parameter checked, defaults for
// the ones not given.
StageInstance make_stage(const StageRegistry& registry, const std::string& type,
                         const nlohmann::json& given) {
  const StageRegistry::Entry* entry = registry.find(type);
  if (entry == nullptr) {
    throw Error("stage type '" + type + "' is not provided by any loaded plugin");
  }
  nlohmann::json values = nlohmann::json::object();
  for (const ParamSpec& spec : entry->descriptor.params) values[spec.name] = spec.default_value;
  for (const auto& [name, value] : given.items()) {
    const ParamSpec* spec = entry->descriptor.param(name);
    if (spec == nullptr) throw Error(type + ": no parameter '" + name + "'");
    if (const std::string expected = spec->check(value); !expected.empty()) {
      throw Error(type + ": parameter '" + name + "': expected " + expected + ", got " +
                  value.dump());
    }
    values[name] = value;
  }
  StageContext context;
  context.node = type;
  context.params = Params(std::move(values));
  context.log = Logger(type);
  return registry.create(type, context);
}

std::size_t port_index(const std::vector<PortSpec>& ports, const std::string& name,
                       const std::string& type) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (ports[i].name == name) return i;
  }
  throw Error(type + " has no port '" + name + "'");
}

template <class T>
T& stage_as(StageInstance& instance, const std::string& type) {
  auto* stage = dynamic_cast<T*>(instance.stage.get());
  if (stage == nullptr) throw Error(type + " is not the kind of stage expected here");
  return *stage;
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
