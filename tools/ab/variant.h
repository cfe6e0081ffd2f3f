// A variant of the measurement chain under test: which chain graph file it runs, which
// of its nodes get another stage type, and which parameters it sets; or what the
// machine measured when the recording was made.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "framework/location.h"

namespace tilth::ab {

// One change to a node of the chain, named as in the chain file ("segment").
struct NodeSetting {
  std::string node;
  std::string param;  // "type" replaces the node's stage type (and drops its parameters)
  nlohmann::json value;
  // For command-line values: typed by the parameter they set, as `tilth run --set`.
  std::optional<std::string> command_line_text;
  std::filesystem::path base_dir;  // relative paths in the value resolve against this
  Location where;

  bool replaces_type() const { return param == "type"; }
};

// Where the replay graph connects to the chain, as "node.port" of the chain file. The
// mask and the registered colour are optional: without them there are no mask figures
// or colour overlays for the variant.
struct ChainPorts {
  std::string raw = "project.raw";
  std::string color = "register.color";
  std::string distance = "estimate.distance";
  std::optional<std::string> mask = "segment.mask";
  std::optional<std::string> registered_color = "register.color";
  // Set when a variants file names the optional ports: then they must exist. The
  // defaults are dropped for a chain without such a node.
  bool optional_ports_named = false;
};

struct Variant {
  std::string name;  // letters, digits, '-' and '_': it names folders and report columns
  std::string description;
  std::filesystem::path chain;
  Location chain_where;  // where the chain was chosen, for messages about it
  ChainPorts ports;
  std::vector<NodeSetting> settings;
  // No chain: what the machine measured live, as an MCAP recording holds it
  // (/tilth/distance), judged as a variant is.
  bool recorded = false;
};

// Throws tilth::Error unless `name` is 1-64 letters, digits, '-' or '_'.
void check_variant_name(const std::string& name, const std::string& where);

}  // namespace tilth::ab
