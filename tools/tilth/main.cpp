// `tilth`: run, check and inspect Tilth graphs.
#include <cstring>
#include <iostream>
#include <string>

#include "commands.h"
#include "external_commands.h"
#include "tilth/error.h"

namespace {

constexpr const char* kUsage = R"(usage: tilth COMMAND [OPTIONS]

Measures the distance from a machine to the soil under crop residue by running a
graph of stages loaded from plugins.

commands:
  run GRAPH        run a graph until its sources end or Ctrl-C
  validate GRAPH   check a graph and report every problem, without running it
  plugins          list the stage types of the plugins found, with their ports
  describe TYPE    print a stage type's ports and full parameter schema
  dot GRAPH        print a graph as Graphviz dot

'tilth COMMAND --help' describes a command's options. Any other COMMAND runs the
program tilth-COMMAND found next to tilth or on PATH.
Plugins are searched next to the graph file, in TILTH_PLUGIN_PATH, and in the build
and install plugin directories.
)";

void print_usage() {
  std::cout << kUsage;
  const auto others = tilth::cli::external_commands();
  if (others.empty()) return;
  std::cout << "\nother commands found:";
  for (const auto& name : others) std::cout << " " << name;
  std::cout << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tilth::cli;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      std::strcmp(argv[1], "help") == 0) {
    print_usage();
    return argc < 2 ? kExitUsage : kExitOk;
  }
  const std::string command = argv[1];
  try {
    if (command == "run") return run_command(argc, argv);
    if (command == "validate") return validate_command(argc, argv);
    if (command == "plugins") return plugins_command(argc, argv);
    if (command == "describe") return describe_command(argc, argv);
    if (command == "dot") return dot_command(argc, argv);
    exec_external_command(command, argc, argv);
  } catch (const tilth::Error& error) {
    std::cerr << "tilth " << command << ": " << error.what() << "\n";
    return kExitUsage;
  }
  std::cerr << "tilth: unknown command '" << command << "'\n" << kUsage;
  return kExitUsage;
}
