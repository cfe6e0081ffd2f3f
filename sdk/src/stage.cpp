#include "tilth/stage.h"
#include "tilth/frame.h"
#include "tilth/stage_descriptor.h"

namespace tilth {

Stage::~Stage() = default;
Source::~Source() = default;
Transform::~Transform() = default;
Sink::~Sink() = default;
Synchronizer::~Synchronizer() = default;
Synchronizer::Output::~Output() = default;

void Frame::set_capture(std::uint64_t frame_id, std::int64_t device_timestamp_ns,
                        std::int64_t host_timestamp_ns) {
  info_.frame_id = frame_id;
  info_.device_timestamp_ns = device_timestamp_ns;
  info_.host_timestamp_ns = host_timestamp_ns;
}

const Packet& Frame::input(std::size_t port) const {
  if (port >= inputs_.size()) {
    throw Error("input port " + std::to_string(port) + " does not exist (the stage has " +
                std::to_string(inputs_.size()) + ")");
  }
  return inputs_[port];
}

void Frame::set_output(std::size_t port, std::shared_ptr<const Message> message) {
  if (port >= outputs_.size()) {
    throw Error("output port " + std::to_string(port) + " does not exist (the stage has " +
                std::to_string(outputs_.size()) + ")");
  }
  outputs_[port] = Packet(info_, std::move(message));
}

std::string_view to_string(StageKind kind) {
  switch (kind) {
    case StageKind::kSource:
      return "source";
    case StageKind::kTransform:
      return "transform";
    case StageKind::kSink:
      return "sink";
    case StageKind::kSynchronizer:
      return "synchronizer";
  }
  return "?";
}

StageKind StageDescriptor::kind() const {
  if (inputs.empty()) return StageKind::kSource;
  if (outputs.empty()) return StageKind::kSink;
  if (input_timing == InputTiming::kOnArrival) return StageKind::kSynchronizer;
  return StageKind::kTransform;
}

const ParamSpec* StageDescriptor::param(std::string_view name) const {
  for (const auto& spec : params) {
    if (spec.name == name) return &spec;
  }
  return nullptr;
}

}  // namespace tilth
