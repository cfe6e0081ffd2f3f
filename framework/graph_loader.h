// Reads a graph file with its includes, substitutes variables and applies command-line
// overrides. Every problem in every file is reported at once, as a GraphError.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "framework/graph_spec.h"

namespace tilth {

struct Setting {
  std::string key;  // "node.param", "runtime.max_in_flight", or a variable name
  std::string value;
};

struct GraphOverrides {
  std::vector<Setting> params;     // --set node.param=value
  std::vector<Setting> variables;  // --var name=value
};

// Parses "key=value"; throws tilth::Error naming the option when there is no '='.
Setting parse_setting(const std::string& option, const std::string& text);

GraphSpec load_graph(const std::filesystem::path& file, const GraphOverrides& overrides = {});

}  // namespace tilth
