// A stage's parameters made from its descriptor, as the graph loader would give them, for
// code that makes a stage outside a graph file: tools that run one stage in process,
// tests and benchmarks (testing/stage_harness.h).
#pragma once

#include <nlohmann/json.hpp>

#include "tilth/params.h"
#include "tilth/stage_descriptor.h"

namespace tilth {

// Every declared parameter, its default unless `overrides` sets it. Throws tilth::Error
// for an undeclared or ill-typed override, naming the stage type and the parameter.
Params stage_params(const StageDescriptor& descriptor, const nlohmann::json& overrides);

}  // namespace tilth
