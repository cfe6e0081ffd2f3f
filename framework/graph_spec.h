// A graph as written, after includes, variables and overrides are resolved but before
// it is checked against the stage types: what the graph files say, and where.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "framework/location.h"

namespace tilth {

struct ParamValue {
  nlohmann::json value;
  Location where;
  // Relative paths resolve against this: the directory of the file that set the value,
  // or the working directory for the command line.
  std::filesystem::path base_dir;
  // Set for --set values, which are typed by the parameter they set.
  std::optional<std::string> command_line_text;
  // Set when the file wrote the value as one of its variables ("${roi}"): wiring the file
  // shares among its nodes rather than a setting of this stage (`tilth ab` keeps it for a
  // stage type replacing the node's).
  std::optional<std::string> variable;
};

struct NodeSpec {
  std::string name;  // qualified: "chain/depth" for a node of an included file
  std::string type;
  Location where;
  std::map<std::string, ParamValue> params;
};

struct EdgeSpec {
  std::string from;  // "node.port"
  std::string to;
  Location where;
};

// A port on a graph file's boundary, declared in its "inputs" or "outputs": what a graph
// that includes the file feeds or reads. A file whose inputs are not fed is a fragment:
// it validates on its own but cannot run.
struct BoundaryPort {
  std::string name;
  std::string endpoint;  // "node.port", qualified as the node
  Location where;
  bool top_level;  // declared by the graph file itself, not by an include
};

enum class FullPolicy { kBlock, kDropOldest };
enum class ErrorPolicy { kSkipFrame, kStop };

struct RuntimeOptions {
  std::size_t max_in_flight = 4;
  FullPolicy when_full = FullPolicy::kBlock;
  ErrorPolicy on_error = ErrorPolicy::kSkipFrame;
};

struct GraphSpec {
  std::filesystem::path file;
  std::string description;
  std::vector<std::filesystem::path> plugins;  // extra plugin libraries named by the graph
  std::vector<NodeSpec> nodes;                 // in the order written
  std::vector<EdgeSpec> edges;
  std::vector<BoundaryPort> inputs;
  std::vector<BoundaryPort> outputs;
  RuntimeOptions runtime;
};

}  // namespace tilth
