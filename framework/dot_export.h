// A validated graph as Graphviz dot: one box per node with its ports, one arrow per
// edge labelled with the message type.
#pragma once

#include <string>

#include "framework/graph_validator.h"

namespace tilth {

std::string to_dot(const ValidatedGraph& graph);

}  // namespace tilth
