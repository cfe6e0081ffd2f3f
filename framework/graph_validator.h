// Checks a graph against the stage types before anything runs: every type, port, edge
// and parameter, all problems at once. The result is what the runtime builds from.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "framework/graph_spec.h"
#include "framework/stage_registry.h"
#include "tilth/params.h"

namespace tilth {

struct InputBinding {
  std::size_t node;  // index of the upstream node in ValidatedGraph::nodes
  std::size_t port;  // its output port
};

struct ResolvedNode {
  std::string name;
  const StageRegistry::Entry* stage;
  Params params;
  Location where;
  std::vector<std::optional<InputBinding>> inputs;  // per input port; none: optional, unconnected
  std::vector<std::size_t> successors;              // distinct, ascending
};

struct ValidatedGraph {
  std::filesystem::path file;
  std::string description;
  std::vector<ResolvedNode> nodes;  // in topological order
  RuntimeOptions runtime;
  // The graph file's declared inputs that nothing in it feeds, as "name (node.port)": a
  // fragment, which a graph including it feeds; it cannot run on its own.
  std::vector<std::string> open_inputs;
  std::vector<std::string> outputs;  // its declared outputs, as "name (node.port)"
};

// Throws GraphError with every problem found.
ValidatedGraph validate_graph(const GraphSpec& graph, const StageRegistry& registry);

}  // namespace tilth
