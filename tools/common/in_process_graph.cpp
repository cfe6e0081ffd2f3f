#include "in_process_graph.h"

#include <filesystem>

#include "framework/graph_session.h"
#include "framework/graph_validator.h"
#include "stop_signals.h"
#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::tools {

InProcessGraph::InProcessGraph(std::string program) : program_(std::move(program)) {
  spec_.file = program_;
  spec_.description = program_;
}

NodeSpec& InProcessGraph::node(const std::string& name) {
  for (NodeSpec& node : spec_.nodes) {
    if (node.name == name) return node;
  }
  throw Error(program_ + ": no node '" + name + "' in its graph");
}

void InProcessGraph::add_node(const std::string& name, const std::string& type,
                              const nlohmann::json& params) {
  NodeSpec node;
  node.name = name;
  node.type = type;
  node.where = Location{program_, "/nodes/" + name};
  for (const auto& [key, value] : params.items()) {
    node.params[key] = ParamValue{value, node.where.child("params").child(key),
                                  std::filesystem::current_path(), std::nullopt, std::nullopt};
  }
  spec_.nodes.push_back(std::move(node));
}

void InProcessGraph::set_from_option(const std::string& node_name, const std::string& param,
                                     const std::string& option, const std::string& text) {
  // JSON, or the text itself when it is not JSON (as --set).
  nlohmann::json value = text;
  try {
    value = parse_json(text, Location{program_, option}.text());
  } catch (const JsonError& error) {
    if (!error.malformed()) throw;
  }
  node(node_name).params[param] = ParamValue{value, Location{program_, option},
                                             std::filesystem::current_path(), text, std::nullopt};
}

void InProcessGraph::add_edge(const std::string& from, const std::string& to) {
  spec_.edges.push_back(
      {from, to, Location{program_, "/edges/" + std::to_string(spec_.edges.size())}});
}

void InProcessGraph::add_stage_type(StageDescriptor descriptor) {
  own_types_.push_back(std::move(descriptor));
}

RunResult InProcessGraph::run(RunLimits limits) {
  const auto registry = load_plugins({});
  for (const StageDescriptor& descriptor : own_types_) registry->add(descriptor, program_);
  Runtime runtime(validate_graph(spec_, *registry), *registry, limits);
  {
    std::lock_guard lock(mutex_);
    running_ = &runtime;
    if (stop_wanted_) runtime.stop();
  }
  const StopSignalWatcher watcher(program_, [&runtime] { runtime.stop(); });
  RunResult result = runtime.run();
  std::lock_guard lock(mutex_);
  running_ = nullptr;
  return result;
}

void InProcessGraph::stop() {
  std::lock_guard lock(mutex_);
  stop_wanted_ = true;
  if (running_ != nullptr) running_->stop();
}

}  // namespace tilth::tools
