// The steps every command takes before it can use a graph: read the graph file, load
// the plugins it can see, and validate it against their stage types.
#pragma once

#include <filesystem>
#include <memory>

#include "framework/graph_loader.h"
#include "framework/graph_validator.h"
#include "framework/stage_registry.h"

namespace tilth {

struct GraphSession {
  std::unique_ptr<StageRegistry> registry;  // outlives the graph, which points into it
  ValidatedGraph graph;
};

// Loads the plugins of the search path (problems with a plugin are logged as warnings)
// and those a graph names (problems are errors).
std::unique_ptr<StageRegistry> load_plugins(const std::filesystem::path& graph_dir,
                                            const std::vector<std::filesystem::path>& named = {});

// Throws GraphError (every problem in the files) or tilth::Error (a named plugin).
GraphSession open_graph(const std::filesystem::path& file, const GraphOverrides& overrides);

}  // namespace tilth
