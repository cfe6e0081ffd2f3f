// A stage type's contract, stated before anything runs: its ports, parameter schema,
// whether frames may run through it concurrently, and how to make one.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "tilth/param_spec.h"
#include "tilth/port_spec.h"
#include "tilth/stage.h"
#include "tilth/stage_context.h"

namespace tilth {

enum class Concurrency {
  kSerial,    // stateful: one frame at a time, in frame order
  kParallel,  // stateless: frames may run concurrently
};

enum class InputTiming {
  kJoinedByFrame,  // the runtime joins the inputs of one frame and calls the stage once
  kOnArrival,      // each source frame is handed over as it arrives: a Synchronizer
};

enum class StageKind { kSource, kTransform, kSink, kSynchronizer };
using StageFactory = std::function<std::unique_ptr<Stage>(const StageContext&)>;
std::string_view to_string(StageKind kind);

struct StageDescriptor {
  std::string type;     // "family.name", unique across loaded plugins
  std::string summary;  // one line
  std::vector<PortSpec> inputs;
  std::vector<PortSpec> outputs;
  std::vector<ParamSpec> params;
  Concurrency concurrency = Concurrency::kSerial;
  InputTiming input_timing = InputTiming::kJoinedByFrame;
  StageFactory create;

  StageKind kind() const;
  const ParamSpec* param(std::string_view name) const;
};

template <class T>
StageFactory factory() {
  return [](const StageContext& context) { return std::make_unique<T>(context); };
}

}  // namespace tilth
