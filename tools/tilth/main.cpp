// `tilth`: run, check and inspect Tilth graphs.
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "external_commands.h"
#include "framework/nearest_names.h"
#include "tilth/abi.h"
#include "tilth/build_stamp.h"
#include "tilth/error.h"
#include "tilth/version.h"

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
  help COMMAND     describe a command's options (as 'tilth COMMAND --help'); for the
                   commands of a group, 'tilth help recording info' describes one

'tilth --version' prints the release and what it was built with. Any other COMMAND runs the
program tilth-COMMAND found next to tilth or on PATH.
Plugins are searched next to the graph file, in TILTH_PLUGIN_PATH, and in
../lib/tilth/plugins from this program's directory.
)";

void print_usage() {
  std::cout << kUsage;
  const auto others = tilth::cli::external_commands();
  if (others.empty()) return;
  std::cout << "\nother commands found:";
  for (const auto& name : others) std::cout << " " << name;
  std::cout << "\n";
}

const std::vector<std::string> kCommands = {"run", "validate", "plugins", "describe", "dot"};

void print_version() {
  std::cout << "tilth " << tilth::version() << "\nbuilt with " << tilth::describe(tilth::kThisBuild)
            << "; plugin ABI " << tilth::kAbiVersion << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace tilth::cli;
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0 ||
      (std::strcmp(argv[1], "help") == 0 && argc == 2)) {
    print_usage();
    return argc < 2 ? kExitUsage : kExitOk;
  }
  if (std::strcmp(argv[1], "--version") == 0 || std::strcmp(argv[1], "version") == 0) {
    print_version();
    return kExitOk;
  }
  // `tilth help COMMAND [SUBCOMMAND]` is `tilth COMMAND [SUBCOMMAND] --help`.
  std::vector<char*> help_arguments;
  if (std::strcmp(argv[1], "help") == 0) {
    static char help_flag[] = "--help";
    help_arguments = {argv[0]};
    help_arguments.insert(help_arguments.end(), argv + 2, argv + argc);
    help_arguments.push_back(help_flag);
    argc = static_cast<int>(help_arguments.size());
    help_arguments.push_back(nullptr);
    argv = help_arguments.data();
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
  std::vector<std::string> known = kCommands;
  for (const auto& name : external_commands()) known.push_back(name);
  std::cerr << "tilth: unknown command '" << command << "'" << tilth::did_you_mean(command, known)
            << "\n\n"
            << kUsage;
  return kExitUsage;
}
