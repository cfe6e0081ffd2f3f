// A stage made from the loaded plugins and driven by a tool's own code, one frame at a
// time, instead of by the runtime: the parameters checked and defaulted as the graph
// loader does.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "framework/stage_registry.h"
#include "tilth/error.h"

namespace tilth::tools {

// A stage of `type` with the `given` parameters, the rest at their defaults. Throws
// tilth::Error naming the type and parameter when no loaded plugin provides the type, a
// parameter does not exist, or a value is not what it expects.
StageInstance make_stage(const StageRegistry& registry, const std::string& type,
                         const nlohmann::json& given);

// The stage as a Source, Transform or Sink; throws tilth::Error naming the type when it
// is not that kind of stage.
template <class T>
T& stage_as(StageInstance& instance, const std::string& type) {
  auto* stage = dynamic_cast<T*>(instance.stage.get());
  if (stage == nullptr) throw Error(type + " is not the kind of stage expected here");
  return *stage;
}

}  // namespace tilth::tools
