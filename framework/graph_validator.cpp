#include "framework/graph_validator.h"

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include "framework/diagnostics.h"
#include "framework/nearest_names.h"

namespace tilth {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Endpoint {
  std::size_t node;
  std::size_t port;
};

std::vector<std::string> port_names(const std::vector<PortSpec>& ports) {
  std::vector<std::string> names;
  for (const auto& port : ports) names.push_back(port.name);
  return names;
}

std::optional<std::size_t> port_index(const std::vector<PortSpec>& ports, const std::string& name) {
  for (std::size_t i = 0; i < ports.size(); ++i) {
    if (ports[i].name == name) return i;
  }
  return std::nullopt;
}

std::string describe_value(const json& value) {
  const std::string text = value.dump();
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}

class Validator {
 public:
  Validator(const GraphSpec& graph, const StageRegistry& registry)
      : graph_(graph), registry_(registry) {}

  ValidatedGraph run() {
    resolve_nodes();
    resolve_edges();
    resolve_boundary();
    check_inputs_connected();
    check_synchronized_sources();
    if (!has_source_ && open_inputs_.empty()) {
      diagnostics_.add({graph_.file.string(), ""}, "the graph has no source stage");
    }
    const std::vector<std::size_t> order = topological_order();
    diagnostics_.throw_if_any();
    return assemble(order);
  }

 private:
  void resolve_nodes() {
    const auto known_types = registry_.type_names();
    for (const auto& spec : graph_.nodes) {
      const auto* entry = registry_.find(spec.type);
      if (entry == nullptr) {
        std::string hint = did_you_mean(spec.type, known_types);
        if (hint.empty()) hint = " (run 'tilth plugins' to list the known types)";
        diagnostics_.add(spec.where.child("type"), "unknown stage type '" + spec.type + "'" + hint);
      } else if (entry->descriptor.kind() == StageKind::kSource) {
        has_source_ = true;
      }
      node_index_[spec.name] = nodes_.size();
      nodes_.push_back({spec.name, entry, Params{}, spec.where, {}, {}});
      inputs_.emplace_back(entry ? entry->descriptor.inputs.size() : 0);
      if (entry) nodes_.back().params = resolve_params(spec, entry->descriptor);
    }
  }

  Params resolve_params(const NodeSpec& spec, const StageDescriptor& descriptor) {
    json values = json::object();
    std::vector<std::string> declared;
    for (const auto& param : descriptor.params) declared.push_back(param.name);
    for (const auto& [name, given] : spec.params) {
      if (descriptor.param(name) == nullptr) {
        diagnostics_.add(given.where, "unknown parameter '" + name + "' of " + descriptor.type +
                                          did_you_mean(name, declared) +
                                          " (its parameters: " + quoted_list(declared) + ")");
      }
    }
    for (const auto& param : descriptor.params) {
      const auto found = spec.params.find(param.name);
      if (found == spec.params.end()) {
        if (param.required()) {
          diagnostics_.add(spec.where, "missing required parameter '" + param.name + "' (" +
                                           std::string(to_string(param.type)) + ": " +
                                           param.description + ")");
        }
        values[param.name] = param.default_value;
        continue;
      }
      const ParamValue& given = found->second;
      json value = given.value;
      const bool is_path = param.type == ParamType::kPath || param.type == ParamType::kOutputPath;
      const bool textual =
          is_path || param.type == ParamType::kString || param.type == ParamType::kChoice;
      if (given.command_line_text && textual) value = *given.command_line_text;
      if (const std::string expected = param.check(value); !expected.empty()) {
        diagnostics_.add(given.where, "parameter '" + param.name + "': expected " + expected +
                                          ", got " + describe_value(value));
        continue;
      }
      if (is_path && !value.get<std::string>().empty()) {
        // What a stage writes lands where the run is started (a service's state
        // directory), never beside a graph file that may sit in a read-only /etc.
        const fs::path base =
            param.type == ParamType::kOutputPath ? fs::current_path() : given.base_dir;
        const fs::path path = value.get<std::string>();
        value = path.is_absolute() ? path.string() : (base / path).lexically_normal().string();
      }
      values[param.name] = std::move(value);
    }
    return Params(std::move(values));
  }

  std::optional<Endpoint> resolve_endpoint(const std::string& text, const Location& where,
                                           bool output) {
    const auto dot = text.rfind('.');
    if (dot == std::string::npos || dot == 0 || dot + 1 == text.size()) {
      diagnostics_.add(where, "expected \"NODE.PORT\", got \"" + text + "\"");
      return std::nullopt;
    }
    const std::string node_name = text.substr(0, dot);
    const std::string port_name = text.substr(dot + 1);
    const auto found = node_index_.find(node_name);
    if (found == node_index_.end()) {
      std::vector<std::string> names;
      for (const auto& node : nodes_) names.push_back(node.name);
      diagnostics_.add(where, "no node named '" + node_name + "'" + did_you_mean(node_name, names));
      return std::nullopt;
    }
    const std::size_t node = found->second;
    const auto* entry = nodes_[node].stage;
    if (entry == nullptr) return std::nullopt;  // already reported as an unknown type
    const auto& ports = output ? entry->descriptor.outputs : entry->descriptor.inputs;
    const auto port = port_index(ports, port_name);
    if (!port) {
      const std::string direction = output ? "output" : "input";
      diagnostics_.add(where, "node '" + node_name + "' (" + entry->descriptor.type + ") has no " +
                                  direction + " port '" + port_name + "'" +
                                  did_you_mean(port_name, port_names(ports)) + "; its " +
                                  direction + "s: " + quoted_list(port_names(ports)));
      return std::nullopt;
    }
    return Endpoint{node, *port};
  }

  void resolve_edges() {
    for (const auto& edge : graph_.edges) {
      const auto from = resolve_endpoint(edge.from, edge.where, true);
      const auto to = resolve_endpoint(edge.to, edge.where, false);
      if (!from || !to) continue;
      const auto& out = nodes_[from->node].stage->descriptor.outputs[from->port];
      const auto& in = nodes_[to->node].stage->descriptor.inputs[to->port];
      if (!in.accepts(out.type)) {
        diagnostics_.add(edge.where, "type mismatch: " + edge.from + " carries " + out.type +
                                         " but " + edge.to + " expects " + in.type);
        continue;
      }
      auto& slot = inputs_[to->node][to->port];
      if (slot) {
        diagnostics_.add(edge.where, "input " + edge.to + " is already fed by " +
                                         graph_.edges[slot->edge].from + " (" +
                                         graph_.edges[slot->edge].where.text() + ")");
        continue;
      }
      slot = Feed{{from->node, from->port}, static_cast<std::size_t>(&edge - graph_.edges.data())};
    }
  }

  // Each declared input and output names a port of the right direction; the graph file's
  // own inputs that nothing feeds are open: fed by a graph that includes the file.
  void resolve_boundary() {
    for (const BoundaryPort& port : graph_.inputs) {
      const auto endpoint = resolve_endpoint(port.endpoint, port.where, false);
      if (!endpoint || !port.top_level || inputs_[endpoint->node][endpoint->port]) continue;
      open_inputs_.insert({endpoint->node, endpoint->port});
      open_input_names_.push_back(port.name + " (" + port.endpoint + ")");
    }
    for (const BoundaryPort& port : graph_.outputs) {
      if (resolve_endpoint(port.endpoint, port.where, true) && port.top_level) {
        output_names_.push_back(port.name + " (" + port.endpoint + ")");
      }
    }
  }

  void check_inputs_connected() {
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (nodes_[i].stage == nullptr) continue;
      const auto& ports = nodes_[i].stage->descriptor.inputs;
      bool any_connected = false;
      for (std::size_t p = 0; p < ports.size(); ++p) {
        const bool fed = inputs_[i][p] || open_inputs_.contains({i, p});
        any_connected = any_connected || fed;
        if (!fed && ports[p].required) {
          diagnostics_.add(nodes_[i].where, "input '" + ports[p].name + "' (" + ports[p].type +
                                                ") is not connected");
        }
      }
      if (!ports.empty() && !any_connected &&
          std::all_of(ports.begin(), ports.end(),
                      [](const auto& port) { return !port.required; })) {
        diagnostics_.add(nodes_[i].where,
                         "none of its inputs is connected (it needs at least one)");
      }
    }
  }

  // A synchronizer's inputs come straight from sources, and those sources enter the graph
  // through it alone: the runtime admits what it emits, not their frames.
  void check_synchronized_sources() {
    std::vector<std::optional<std::size_t>> synchronized_by(nodes_.size());
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      if (kind(i) != StageKind::kSynchronizer) continue;
      for (const auto& feed : inputs_[i]) {
        if (!feed) continue;
        const std::size_t from = feed->binding.node;
        const auto& edge = graph_.edges[feed->edge];
        if (kind(from) != StageKind::kSource) {
          diagnostics_.add(edge.where, edge.to + " belongs to synchronizer '" + nodes_[i].name +
                                           "', whose inputs must come straight from sources; '" +
                                           nodes_[from].name + "' is a " +
                                           std::string(to_string(kind(from))));
        } else {
          synchronized_by[from] = i;
        }
      }
    }
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      for (const auto& feed : inputs_[i]) {
        if (!feed) continue;
        const auto& synchronizer = synchronized_by[feed->binding.node];
        if (!synchronizer || *synchronizer == i) continue;
        const auto& edge = graph_.edges[feed->edge];
        diagnostics_.add(edge.where, "source '" + nodes_[feed->binding.node].name +
                                         "' feeds synchronizer '" + nodes_[*synchronizer].name +
                                         "', so it enters the graph there and can feed nothing "
                                         "else; connect '" +
                                         nodes_[i].name + "' to the synchronizer's outputs");
      }
    }
  }

  StageKind kind(std::size_t node) const {
    return nodes_[node].stage ? nodes_[node].stage->descriptor.kind() : StageKind::kTransform;
  }

  std::set<std::size_t> predecessors(std::size_t node) const {
    std::set<std::size_t> result;
    for (const auto& feed : inputs_[node]) {
      if (feed) result.insert(feed->binding.node);
    }
    return result;
  }

  // Kahn's algorithm; nodes left over lie on or behind a cycle, which is reported.
  std::vector<std::size_t> topological_order() {
    std::vector<std::size_t> remaining(nodes_.size());
    std::vector<std::set<std::size_t>> successors(nodes_.size());
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
      const auto before = predecessors(i);
      remaining[i] = before.size();
      for (std::size_t p : before) successors[p].insert(i);
    }
    std::vector<std::size_t> order;
    std::vector<std::size_t> ready;
    for (std::size_t i = nodes_.size(); i-- > 0;) {
      if (remaining[i] == 0) ready.push_back(i);
    }
    while (!ready.empty()) {
      const std::size_t node = ready.back();
      ready.pop_back();
      order.push_back(node);
      for (std::size_t next : successors[node]) {
        if (--remaining[next] == 0) ready.push_back(next);
      }
    }
    if (order.size() < nodes_.size()) report_cycle(remaining);
    return order;
  }

  void report_cycle(const std::vector<std::size_t>& remaining) {
    // Walk backwards through unfinished predecessors until a node repeats.
    std::size_t node = 0;
    while (remaining[node] == 0) ++node;
    std::vector<std::size_t> path;
    std::vector<bool> on_path(nodes_.size());
    while (!on_path[node]) {
      on_path[node] = true;
      path.push_back(node);
      for (std::size_t p : predecessors(node)) {
        if (remaining[p] > 0) {
          node = p;
          break;
        }
      }
    }
    const auto start = std::find(path.begin(), path.end(), node);
    std::vector<std::size_t> cycle(start, path.end());
    std::reverse(cycle.begin(), cycle.end());
    std::string text;
    for (std::size_t n : cycle) text += nodes_[n].name + " -> ";
    text += nodes_[cycle.front()].name;
    diagnostics_.add(nodes_[cycle.front()].where, "the graph has a cycle: " + text);
  }

  ValidatedGraph assemble(const std::vector<std::size_t>& order) {
    std::vector<std::size_t> position(nodes_.size());
    for (std::size_t i = 0; i < order.size(); ++i) position[order[i]] = i;
    ValidatedGraph result{graph_.file,    graph_.description, {},
                          graph_.runtime, open_input_names_,  output_names_};
    for (std::size_t original : order) {
      ResolvedNode node = std::move(nodes_[original]);
      for (const auto& feed : inputs_[original]) {
        node.inputs.push_back(feed ? std::optional<InputBinding>(InputBinding{
                                         position[feed->binding.node], feed->binding.port})
                                   : std::nullopt);
      }
      result.nodes.push_back(std::move(node));
    }
    for (std::size_t i = 0; i < result.nodes.size(); ++i) {
      std::set<std::size_t> before;
      for (const auto& input : result.nodes[i].inputs) {
        if (input) before.insert(input->node);
      }
      for (std::size_t p : before) result.nodes[p].successors.push_back(i);
    }
    return result;
  }

  struct Feed {
    InputBinding binding;
    std::size_t edge;
  };

  const GraphSpec& graph_;
  const StageRegistry& registry_;
  Diagnostics diagnostics_;
  std::vector<ResolvedNode> nodes_;
  // name -> index in nodes_; the loader gives every node its own name.
  std::unordered_map<std::string, std::size_t> node_index_;
  std::vector<std::vector<std::optional<Feed>>> inputs_;       // per node, per input port
  std::set<std::pair<std::size_t, std::size_t>> open_inputs_;  // (node, input port)
  std::vector<std::string> open_input_names_;
  std::vector<std::string> output_names_;
  bool has_source_ = false;
};

}  // namespace

ValidatedGraph validate_graph(const GraphSpec& graph, const StageRegistry& registry) {
  return Validator(graph, registry).run();
}

}  // namespace tilth
