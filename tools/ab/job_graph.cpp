// The replay graph file of a job (variant "wide", recording "case_c"):
//   {"include": [{"file": "/abs/measurement-chain.json", "as": "wide@case_c"}],
//    "nodes": {"recording": {"type": "recording.image_folder", "params": {"path": "/abs/case_c"}},
//              "evaluation": {"type": "sinks.evaluation", "params": {"path": ".../frames.jsonl"}}},
//    "edges": [["recording.raw", "wide@case_c/project.raw"], ...],
//    "runtime": {"max_in_flight": 4, "when_full": "block", "on_error": "skip"}}
#include "job_graph.h"

#include <fstream>

#include <nlohmann/json.hpp>

#include "framework/nearest_names.h"
#include "mcap/mcap_reader.h"
#include "mcap/recording_layout.h"
#include "tilth/error.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

std::string node_of(const std::string& endpoint) { return endpoint.substr(0, endpoint.rfind('.')); }

std::vector<std::string> node_names(const GraphSpec& graph) {
  std::vector<std::string> names;
  for (const auto& node : graph.nodes) names.push_back(node.name);
  return names;
}

bool has_node(const GraphSpec& graph, const std::string& name) {
  for (const auto& node : graph.nodes) {
    if (node.name == name) return true;
  }
  return false;
}

NodeSpec* find_node(GraphSpec& graph, const std::string& name) {
  for (auto& node : graph.nodes) {
    if (node.name == name) return &node;
  }
  return nullptr;
}

bool holds_what_was_measured(const Recording& recording) {
  if (recording.format != RecordingFormat::kMcap) return false;
  const mcap::McapReader reader(recording.path);
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.topic == mcap::kDistanceTopic) return true;
  }
  return false;
}

void take_problems(const GraphError& error, Diagnostics& problems) {
  for (const auto& item : error.diagnostics().items()) problems.add(item.where, item.message);
}

json runtime_of(const JobOptions& options) {
  return {{"max_in_flight", options.max_in_flight}, {"when_full", "block"}, {"on_error", "skip"}};
}

// A recorded variant's graph: the player's recorded distance judged against its truth.
json recorded_graph(const Variant& variant, const Recording& recording, json evaluation_params,
                    const JobOptions& options) {
  return {
      {"description", "tilth ab: what the machine measured ('" + variant.name +
                          "'), as recorded in " + recording.path.string()},
      {"nodes",
       {{"recording",
         {{"type", player_type(recording.format)},
          {"params", {{"path", recording.path.string()}}}}},
        {"evaluation", {{"type", "sinks.evaluation"}, {"params", evaluation_params}}}}},
      {"edges", json::array({{"recording.distance", "evaluation.distance"},
                             {"recording.truth", "evaluation.truth"}})},
      {"runtime", runtime_of(options)},
  };
}

json replay_graph(const Variant& variant, const Recording& recording, const JobFiles& files,
                  const JobOptions& options) {
  const std::string chain = job_label(variant, recording) + "/";
  json evaluation_params = {{"path", files.frames.string()}};
  if (options.save_images && !variant.recorded) evaluation_params["save_images"] = true;
  if (variant.recorded) return recorded_graph(variant, recording, evaluation_params, options);
  json edges = json::array({
      {"recording.raw", chain + variant.ports.raw},
      {"recording.color", chain + variant.ports.color},
      {chain + variant.ports.distance, "evaluation.distance"},
      {"recording.truth", "evaluation.truth"},
  });
  if (variant.ports.mask) edges.push_back({chain + *variant.ports.mask, "evaluation.mask"});
  if (variant.ports.registered_color && options.save_images && options.save_color) {
    edges.push_back({chain + *variant.ports.registered_color, "evaluation.color"});
  }
  return {
      {"description",
       "tilth ab: variant '" + variant.name + "' on recording " + recording.path.string()},
      {"include", json::array({{{"file", fs::absolute(variant.chain).string()},
                                {"as", job_label(variant, recording)}}})},
      {"nodes",
       {{"recording",
         {{"type", player_type(recording.format)},
          {"params", {{"path", recording.path.string()}}}}},
        {"evaluation", {{"type", "sinks.evaluation"}, {"params", evaluation_params}}}}},
      {"edges", edges},
      {"runtime", runtime_of(options)},
  };
}

void write_file(const fs::path& file, const std::string& text) {
  std::error_code error;
  fs::create_directories(file.parent_path(), error);
  std::ofstream out(file);
  out << text;
  if (error || !out.flush()) throw Error(file.string() + ": cannot write the file");
}

// Type replacements first: a replaced node keeps the parameters the chain file wires to
// its variables ("roi": "${roi}") that the new type has too, so that it works on what its
// neighbours work on, and the parameters the variant sets.
void apply_settings(const Variant& variant, const std::string& prefix,
                    const StageRegistry& registry, GraphSpec& graph) {
  for (const bool types : {true, false}) {
    for (const auto& setting : variant.settings) {
      if (setting.replaces_type() != types) continue;
      NodeSpec* node = find_node(graph, prefix + setting.node);
      if (node == nullptr) continue;  // reported by check_variant
      if (types) {
        node->type = setting.value.get<std::string>();  // check_variant made sure
        node->where = setting.where;
        const StageRegistry::Entry* replacing = registry.find(node->type);
        std::erase_if(node->params, [&](const auto& param) {
          return !param.second.variable || replacing == nullptr ||
                 replacing->descriptor.param(param.first) == nullptr;
        });
      } else {
        node->params[setting.param] = {setting.value, setting.where, setting.base_dir,
                                       setting.command_line_text, std::nullopt};
      }
    }
  }
}

}  // namespace

std::string job_label(const Variant& variant, const Recording& recording) {
  return variant.name + "@" + recording.name;
}

std::vector<fs::path> check_variant(Variant& variant, const GraphOverrides& variables,
                                    Diagnostics& problems) {
  if (variant.recorded) {
    for (const auto& setting : variant.settings) {
      problems.add(setting.where, "variant '" + variant.name +
                                      "' is recorded: it runs no chain, so it takes no settings");
    }
    return {};
  }
  GraphSpec chain;
  try {
    chain = load_graph(variant.chain, {{}, variables.variables});
  } catch (const GraphError& error) {
    take_problems(error, problems);
    return {};
  }
  const std::vector<std::string> names = node_names(chain);
  const std::string in_chain = " in the chain " + variant.chain.string();
  for (const auto& setting : variant.settings) {
    if (!has_node(chain, setting.node)) {
      problems.add(setting.where, "no node '" + setting.node + "'" + in_chain +
                                      did_you_mean(setting.node, names) +
                                      " (its nodes: " + quoted_list(names) + ")");
    } else if (setting.replaces_type() && !setting.value.is_string()) {
      problems.add(setting.where, "expected a stage type name, got " + setting.value.dump());
    }
  }
  auto& ports = variant.ports;
  for (const std::string* port : {&ports.raw, &ports.color, &ports.distance}) {
    if (!has_node(chain, node_of(*port))) {
      problems.add(variant.chain_where, "variant '" + variant.name + "': no node '" +
                                            node_of(*port) + "'" + in_chain + " for " + *port +
                                            "; name the chain's ports in a variants file");
    }
  }
  for (auto* port : {&ports.mask, &ports.registered_color}) {
    if (!*port || has_node(chain, node_of(**port))) continue;
    if (ports.optional_ports_named) {
      problems.add(variant.chain_where, "variant '" + variant.name + "': no node '" +
                                            node_of(**port) + "'" + in_chain + " for " + **port);
    }
    port->reset();
  }
  return chain.plugins;
}

void check_stage_types(const Variant& variant, const StageRegistry& registry,
                       Diagnostics& problems) {
  for (const auto& setting : variant.settings) {
    if (!setting.replaces_type() || !setting.value.is_string()) continue;
    const std::string type = setting.value.get<std::string>();
    if (registry.find(type) != nullptr) continue;
    problems.add(setting.where, "unknown stage type '" + type + "'" +
                                    did_you_mean(type, registry.type_names()) +
                                    " (run 'tilth plugins' to list the known types)");
  }
}

std::optional<ValidatedGraph> job_graph(const Variant& variant, const Recording& recording,
                                        const JobFiles& files, const JobOptions& options,
                                        const StageRegistry& registry, Diagnostics& problems) {
  if (variant.recorded && !holds_what_was_measured(recording)) {
    problems.add(variant.chain_where,
                 "variant '" + variant.name + "' is what the machine measured, and " +
                     recording.path.string() + " does not hold it: " +
                     (recording.format == RecordingFormat::kMcap
                          ? "no " + std::string(mcap::kDistanceTopic) +
                                " channel (recorded without mcap.writer's distance input)"
                          : "only MCAP recordings do (docs/mcap.md)"));
    return std::nullopt;
  }
  write_file(files.graph, replay_graph(variant, recording, files, options).dump(2) + "\n");
  try {
    // --var sets the chains' variables; a recorded variant has no chain.
    GraphSpec graph = load_graph(
        files.graph, {{}, variant.recorded ? std::vector<Setting>{} : options.variables.variables});
    apply_settings(variant, job_label(variant, recording) + "/", registry, graph);
    return validate_graph(graph, registry);
  } catch (const GraphError& error) {
    take_problems(error, problems);
    return std::nullopt;
  }
}

}  // namespace tilth::ab
