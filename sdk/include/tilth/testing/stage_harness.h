// Runs one stage outside a graph, for a plugin's own tests and benchmarks (as MediaPipe's
// CalculatorRunner and GStreamer's GstHarness do): the stage is made from its descriptor
// with the parameters the graph loader would give it, and frames go through it one by one.
// Link the plugin's stages (tilth_add_plugin's tilth_NAME_stages) and a TILTH_PLUGIN of
// the test's own.
#pragma once

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tilth/error.h"
#include "tilth/frame.h"
#include "tilth/stage_descriptor.h"
#include "tilth/stage_params.h"

namespace tilth::testing {

class TransformHarness {
 public:
  explicit TransformHarness(StageDescriptor descriptor,
                            const nlohmann::json& overrides = nlohmann::json::object())
      : descriptor_(std::move(descriptor)) {
    StageContext context;
    context.node = "under_test";
    context.params = stage_params(descriptor_, overrides);
    context.log = Logger(context.node);
    stage_ = descriptor_.create(context);
    transform_ = dynamic_cast<Transform*>(stage_.get());
    if (transform_ == nullptr) throw Error(descriptor_.type + " is not a transform");
  }

  // One frame through the stage; an input not given (or null) is an empty packet, as an
  // unconnected optional input is, and so is an output the stage left unset. The packets
  // own the messages: keep them (or copy the message) while reading an output.
  std::vector<Packet> run(std::vector<std::shared_ptr<const Message>> inputs,
                          std::uint64_t frame_id = 0) {
    FrameInfo info;
    info.sequence = frame_id;
    info.frame_id = frame_id;
    return run(std::move(inputs), info);
  }
  // The same, with the frame's capture times: for stages that keep time.
  std::vector<Packet> run(std::vector<std::shared_ptr<const Message>> inputs,
                          const FrameInfo& info) {
    std::vector<Packet> in(std::max(inputs.size(), descriptor_.inputs.size()));
    for (std::size_t port = 0; port < inputs.size(); ++port) {
      if (inputs[port] != nullptr) in[port] = Packet(info, std::move(inputs[port]));
    }
    std::vector<Packet> out(descriptor_.outputs.size());
    Frame frame(info, in, out);
    transform_->process(frame);
    return out;
  }

  // The end of the stream, which the runtime signals once after the last frame: where a
  // stage that keeps state reports or flushes it.
  void finish() { stage_->finish(); }

 private:
  StageDescriptor descriptor_;
  std::unique_ptr<Stage> stage_;
  Transform* transform_ = nullptr;
};

}  // namespace tilth::testing
