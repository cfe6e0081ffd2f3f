#include "framework/dot_export.h"

#include <sstream>

namespace tilth {
namespace {

std::string quoted(const std::string& text) {
  std::string escaped = "\"";
  for (char c : text) {
    if (c == '\n') {
      escaped += "\\n";
      continue;
    }
    if (c == '"' || c == '\\') escaped += '\\';
    escaped += c;
  }
  return escaped + "\"";
}

}  // namespace

std::string to_dot(const ValidatedGraph& graph) {
  std::ostringstream out;
  out << "digraph tilth {\n  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n";
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const auto& node = graph.nodes[i];
    out << "  n" << i << " [label=" << quoted(node.name + "\n" + node.stage->descriptor.type)
        << "];\n";
  }
  for (std::size_t i = 0; i < graph.nodes.size(); ++i) {
    const auto& node = graph.nodes[i];
    const auto& inputs = node.stage->descriptor.inputs;
    for (std::size_t p = 0; p < node.inputs.size(); ++p) {
      if (!node.inputs[p]) continue;
      const auto& from = *node.inputs[p];
      const auto& out_port = graph.nodes[from.node].stage->descriptor.outputs[from.port];
      out << "  n" << from.node << " -> n" << i
          << " [label=" << quoted(out_port.name + " → " + inputs[p].name + "\n" + out_port.type)
          << "];\n";
    }
  }
  out << "}\n";
  return out.str();
}

}  // namespace tilth
