// The options shared by the commands that take a graph file: --set, --var.
#pragma once

#include <set>
#include <string>

#include "command_line.h"
#include "framework/graph_loader.h"

namespace tilth::cli {

inline const std::set<std::string> kGraphOptions = {"--set", "--var"};

constexpr const char* kGraphOptionsHelp =
    "  --set NODE.PARAM=VALUE  override a node parameter (or runtime.OPTION=VALUE);\n"
    "                          VALUE is JSON, or text when it is not valid JSON\n"
    "  --var NAME=VALUE        set a graph variable, used as ${NAME} in the files\n";

GraphOverrides graph_overrides(const CommandLine& line);

}  // namespace tilth::cli
