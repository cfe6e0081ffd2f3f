// validate, plugins, describe, dot: the commands that look at graphs and stage types
// without running anything.
#include <iostream>

#include "command_line.h"
#include "commands.h"
#include "framework/diagnostics.h"
#include "framework/dot_export.h"
#include "framework/graph_session.h"
#include "framework/nearest_names.h"
#include "framework/stage_reference.h"
#include "graph_options.h"

namespace tilth::cli {
namespace {

bool wants_help(const CommandLine& line, const char* usage) {
  if (!line.flag("--help")) return false;
  std::cout << usage;
  return true;
}

}  // namespace

GraphOverrides graph_overrides(const CommandLine& line) {
  GraphOverrides overrides;
  for (const auto& text : line.values("--set"))
    overrides.params.push_back(parse_setting("--set", text));
  for (const auto& text : line.values("--var")) {
    overrides.variables.push_back(parse_setting("--var", text));
  }
  return overrides;
}

int validate_command(int argc, char** argv) {
  const CommandLine line(argc, argv, 2, kGraphOptions, {"--help"});
  const std::string usage =
      std::string(
          "usage: tilth validate GRAPH [--set NODE.PARAM=VALUE]... [--var NAME=VALUE]...\n\n"
          "Checks a graph file, its includes and parameters against the stage types and\n"
          "prints every problem with its file and JSON pointer. Exit code 0 when valid.\n\n") +
      kGraphOptionsHelp;
  if (wants_help(line, usage.c_str())) return kExitOk;
  if (line.positional().size() != 1) {
    std::cerr << usage;
    return kExitUsage;
  }
  try {
    const auto session = open_graph(line.positional()[0], graph_overrides(line));
    const ValidatedGraph& graph = session.graph;
    std::cout << line.positional()[0] << ": valid, " << graph.nodes.size() << " nodes";
    if (!graph.open_inputs.empty()) {
      std::cout << "; a fragment: a graph that includes it feeds its inputs "
                << quoted_list(graph.open_inputs);
    }
    if (!graph.outputs.empty()) std::cout << "; outputs " << quoted_list(graph.outputs);
    std::cout << "\n";
    return kExitOk;
  } catch (const GraphError& error) {
    std::cerr << error.what() << "\n";
    std::cerr << error.diagnostics().items().size() << " problem(s)\n";
    return kExitUsage;
  }
}

int plugins_command(int argc, char** argv) {
  const CommandLine line(argc, argv, 2, {}, {"--help"});
  constexpr const char* kUsageText =
      "usage: tilth plugins\n\nLists every stage type of the plugins on the search path, with its\n"
      "ports (name:message type).\n";
  if (wants_help(line, kUsageText)) return kExitOk;
  const auto registry = load_plugins(".");
  std::string plugin;
  for (const auto& entry : registry->entries()) {
    if (entry.plugin != plugin) {
      plugin = entry.plugin;
      std::cout << plugin << "  (" << entry.file.string() << ")\n";
    }
    std::cout << "  " << stage_line(entry) << "\n";
  }
  return kExitOk;
}

int describe_command(int argc, char** argv) {
  const CommandLine line(argc, argv, 2, {}, {"--help", "--markdown"});
  constexpr const char* kUsageText =
      "usage: tilth describe TYPE [--markdown]\n\nPrints a stage type's ports and parameter schema "
      "(type, default, allowed\nvalues, unit, description). --markdown prints it as in docs/.\n";
  if (wants_help(line, kUsageText)) return kExitOk;
  if (line.positional().size() != 1) {
    std::cerr << kUsageText;
    return kExitUsage;
  }
  const auto registry = load_plugins(".");
  const std::string& type = line.positional()[0];
  const auto* entry = registry->find(type);
  if (entry == nullptr) {
    std::cerr << "tilth describe: unknown stage type '" << type << "'"
              << did_you_mean(type, registry->type_names()) << "\n";
    return kExitUsage;
  }
  std::cout << stage_reference(*entry, line.flag("--markdown"));
  return kExitOk;
}

int dot_command(int argc, char** argv) {
  const CommandLine line(argc, argv, 2, kGraphOptions, {"--help"});
  const std::string usage =
      std::string(
          "usage: tilth dot GRAPH [--set ...] [--var ...]\n\nPrints the graph as Graphviz dot "
          "(tilth dot g.json | dot -Tsvg > g.svg).\n\n") +
      kGraphOptionsHelp;
  if (wants_help(line, usage.c_str())) return kExitOk;
  if (line.positional().size() != 1) {
    std::cerr << usage;
    return kExitUsage;
  }
  try {
    std::cout << to_dot(open_graph(line.positional()[0], graph_overrides(line)).graph);
    return kExitOk;
  } catch (const GraphError& error) {
    std::cerr << error.what() << "\n";
    return kExitUsage;
  }
}

}  // namespace tilth::cli
