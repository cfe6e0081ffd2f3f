// Graph file format (docs/graph-format.md):
//   { "description": "...", "plugins": [...], "variables": {...},
//     "include": [{"file": "chain.json", "as": "chain", "variables": {...}}],
//     "nodes": {"name": {"type": "family.stage", "params": {...}}},
//     "edges": [["a.out", "b.in"], {"from": "a.out", "to": "b.in"}],
//     "inputs": {"raw": "a.in"}, "outputs": {"distance": "b.out"},
//     "runtime": {"max_in_flight": 4, "when_full": "block", "on_error": "skip"} }
// An included file is looked for beside the including one, then among the shipped graphs
// (share/tilth/graphs). A node of the including file with the name of an included node replaces it
// when it names a type, overrides only the parameters it lists otherwise, and removes it (with its
// edges, inputs and outputs) when it is null.
#include "framework/graph_loader.h"

#include <algorithm>
#include <regex>
#include <set>
#include <unordered_map>

#include "framework/diagnostics.h"
#include "framework/install_layout.h"
#include "framework/nearest_names.h"
#include "tilth/json_input.h"

namespace tilth {
namespace {

// A reference to a variable in a parameter's value: ${NAME}.
const std::regex kReference(R"(\$\{([A-Za-z_][A-Za-z0-9_]*)\})");

// ordered_json keeps nodes and keys in the order written, so problems are reported in
// file order.
using json = nlohmann::ordered_json;
namespace fs = std::filesystem;

const std::vector<std::string> kTopLevelKeys = {"description", "plugins", "variables",
                                                "include",     "inputs",  "outputs",
                                                "nodes",       "edges",   "runtime"};
const std::vector<std::string> kNodeKeys = {"type", "params", "description"};
const std::vector<std::string> kIncludeKeys = {"file", "as", "variables"};
const std::vector<std::string> kRuntimeKeys = {"max_in_flight", "when_full", "on_error"};

std::string scalar_text(const json& value) {
  return value.is_string() ? value.get<std::string>() : value.dump();
}

class Loader {
 public:
  Loader(const GraphOverrides& overrides, Diagnostics& diagnostics) : diagnostics_(diagnostics) {
    for (const auto& variable : overrides.variables) {
      command_line_variables_[variable.key] =
          parse_value(variable.value, {"command line", "--var " + variable.key});
    }
  }

  void load(const fs::path& file, const std::string& prefix, const json& include_variables,
            const Location& included_from) {
    const std::string name = file.lexically_normal().string();
    if (std::find(chain_.begin(), chain_.end(), name) != chain_.end()) {
      std::string cycle;
      for (const auto& link : chain_) cycle += link + " -> ";
      diagnostics_.add(included_from, "include cycle: " + cycle + name);
      return;
    }
    std::string text;
    try {
      text = read_json_text(file, "graph file '" + name + "'");
    } catch (const JsonError& error) {
      diagnostics_.add(included_from.file.empty() ? Location{name, ""} : included_from,
                       error.reason());
      return;
    }
    json document;
    try {
      document = parse_ordered_json(text, name, {.comments = true});
    } catch (const JsonError& error) {
      diagnostics_.add({name, error.pointer(), error.line(), error.column()},
                       (error.malformed() ? "malformed JSON: " : "") + error.reason());
      return;
    }
    const Location root{name, ""};
    if (!document.is_object()) {
      diagnostics_.add(root, "expected a JSON object with \"nodes\" and \"edges\"");
      return;
    }
    chain_.push_back(name);
    check_keys(document, root, kTopLevelKeys, "graph file");
    const json variables = resolve_variables(document, root, include_variables);
    const fs::path dir = file.parent_path();

    if (chain_.size() == 1 && document.contains("description") &&
        document["description"].is_string()) {
      graph_.description = document["description"].get<std::string>();
    }
    load_plugins(document, root, dir);
    load_includes(document, root, dir, prefix, variables);
    load_nodes(document, root, dir, prefix, variables);
    load_edges(document, root, prefix);
    load_boundary(document, root, prefix, "inputs", graph_.inputs);
    load_boundary(document, root, prefix, "outputs", graph_.outputs);
    load_runtime(document, root);
    chain_.pop_back();
  }

  // A --var that no file of the graph declares would change nothing: a typing slip.
  void check_command_line_variables() {
    const std::vector<std::string> declared(declared_variables_.begin(), declared_variables_.end());
    for (const auto& [name, value] : command_line_variables_) {
      if (declared_variables_.contains(name)) continue;
      diagnostics_.add({"command line", "--var " + name},
                       "no file of the graph declares a variable '" + name + "'" +
                           did_you_mean(name, declared) + " (declared: " + quoted_list(declared) +
                           ")");
    }
  }

  void apply(const std::vector<Setting>& settings) {
    for (const auto& setting : settings) {
      const Location where{"command line", "--set " + setting.key};
      const auto dot = setting.key.find('.');
      if (dot == std::string::npos || dot == 0 || dot + 1 == setting.key.size()) {
        diagnostics_.add(where, "expected NODE.PARAM=VALUE");
        continue;
      }
      const std::string node_name = setting.key.substr(0, dot);
      const std::string param = setting.key.substr(dot + 1);
      if (node_name == "runtime") {
        json runtime = {{param, parse_value(setting.value, where)}};
        apply_runtime(runtime, where);
        continue;
      }
      NodeSpec* node = find_node(node_name);
      if (node == nullptr) {
        diagnostics_.add(
            where, "no node named '" + node_name + "'" + did_you_mean(node_name, node_names()));
        continue;
      }
      node->params[param] = {nlohmann::json(parse_value(setting.value, where)), where,
                             fs::current_path(), setting.value, std::nullopt};
    }
  }

  GraphSpec take(const fs::path& file) {
    graph_.file = file;
    return std::move(graph_);
  }

 private:
  // JSON, or the text itself when it is not JSON; JSON that is refused (a duplicate key,
  // a number beyond double range) is reported.
  json parse_value(const std::string& text, const Location& where) {
    try {
      return parse_ordered_json(text, where.text());
    } catch (const JsonError& error) {
      if (error.malformed()) return text;
      diagnostics_.add(
          where, (error.pointer().empty() ? "" : "at " + error.pointer() + ": ") + error.reason());
      return nullptr;
    }
  }

  void check_keys(const json& object, const Location& where, const std::vector<std::string>& known,
                  const std::string& what) {
    for (const auto& [key, value] : object.items()) {
      if (std::find(known.begin(), known.end(), key) == known.end()) {
        diagnostics_.add(where.child(key), "unknown key '" + key + "' in " + what +
                                               did_you_mean(key, known) + " (expected one of " +
                                               quoted_list(known) + ")");
      }
    }
  }

  // The file's own variables, overridden by those its includer passes, overridden by the
  // command line.
  json resolve_variables(const json& document, const Location& root, const json& from_includer) {
    json variables = json::object();
    if (document.contains("variables")) {
      if (document["variables"].is_object()) {
        variables = document["variables"];
        for (const auto& [key, value] : variables.items()) declared_variables_.insert(key);
      } else {
        diagnostics_.add(root.child("variables"), "expected an object of name: value");
      }
    }
    for (const auto& [key, value] : from_includer.items()) variables[key] = value;
    for (const auto& [key, value] : command_line_variables_) variables[key] = value;
    return variables;
  }

  // "${name}" alone becomes the variable's value with its type; "${name}" inside a
  // longer string is replaced by its text.
  json substitute(const json& value, const json& variables, const Location& where) {
    if (value.is_object()) {
      json result = json::object();
      for (const auto& [key, item] : value.items()) {
        result[key] = substitute(item, variables, where.child(key));
      }
      return result;
    }
    if (value.is_array()) {
      json result = json::array();
      for (std::size_t i = 0; i < value.size(); ++i) {
        result.push_back(substitute(value[i], variables, where.child(std::to_string(i))));
      }
      return result;
    }
    if (!value.is_string()) return value;
    if (const auto variable = whole_reference(value)) return lookup(*variable, variables, where);
    const std::string text = value.get<std::string>();
    std::string result;
    auto begin = text.cbegin();
    for (std::sregex_iterator it(text.begin(), text.end(), kReference), end; it != end; ++it) {
      result.append(begin, text.cbegin() + it->position());
      result += scalar_text(lookup((*it)[1], variables, where));
      begin = text.cbegin() + it->position() + it->length();
    }
    result.append(begin, text.cend());
    return result;
  }

  // The variable a value is, when it is one reference and nothing else ("${roi}"): the
  // variable's value itself, of any JSON type.
  static std::optional<std::string> whole_reference(const json& value) {
    if (!value.is_string()) return std::nullopt;
    const std::string text = value.get<std::string>();
    std::smatch whole;
    if (!std::regex_match(text, whole, kReference)) return std::nullopt;
    return whole[1].str();
  }

  // Relative paths in a value resolve against the file's directory, unless the value
  // starts with a variable set on the command line (`--var log=run.csv`): that path was
  // typed in the working directory.
  fs::path base_dir(const json& value, const fs::path& file_dir) const {
    if (!value.is_string()) return file_dir;
    const std::string text = value.get<std::string>();
    std::smatch leading;
    if (std::regex_search(text, leading, kReference, std::regex_constants::match_continuous) &&
        command_line_variables_.contains(leading[1])) {
      return fs::current_path();
    }
    return file_dir;
  }

  json lookup(const std::string& name, const json& variables, const Location& where) {
    if (variables.contains(name)) return variables[name];
    std::vector<std::string> known;
    for (const auto& [key, value] : variables.items()) known.push_back(key);
    diagnostics_.add(where, "unknown variable '" + name + "'" + did_you_mean(name, known) +
                                " (defined: " + quoted_list(known) + ")");
    return nullptr;
  }

  void load_plugins(const json& document, const Location& root, const fs::path& dir) {
    if (!document.contains("plugins")) return;
    const json& plugins = document["plugins"];
    if (!plugins.is_array()) {
      diagnostics_.add(root.child("plugins"), "expected an array of plugin library paths");
      return;
    }
    for (std::size_t i = 0; i < plugins.size(); ++i) {
      if (!plugins[i].is_string()) {
        diagnostics_.add(root.child("plugins").child(std::to_string(i)),
                         "expected a plugin library path (a string)");
        continue;
      }
      graph_.plugins.push_back(dir / plugins[i].get<std::string>());
    }
  }

  void load_includes(const json& document, const Location& root, const fs::path& dir,
                     const std::string& prefix, const json& variables) {
    if (!document.contains("include")) return;
    const json& includes = document["include"];
    const Location list = root.child("include");
    if (!includes.is_array()) {
      diagnostics_.add(list, "expected an array of {\"file\": ..., \"as\": ...}");
      return;
    }
    for (std::size_t i = 0; i < includes.size(); ++i) {
      const Location where = list.child(std::to_string(i));
      json entry = includes[i].is_string() ? json{{"file", includes[i]}} : includes[i];
      if (!entry.is_object() || !entry.contains("file") || !entry["file"].is_string()) {
        diagnostics_.add(where, "expected a file name or {\"file\": ..., \"as\": ...}");
        continue;
      }
      check_keys(entry, where, kIncludeKeys, "include");
      std::string nested_prefix = prefix;
      if (entry.contains("as")) {
        const json& as = entry["as"];
        if (!as.is_string() || as.get<std::string>().empty() ||
            as.get<std::string>().find_first_of("./") != std::string::npos) {
          diagnostics_.add(where.child("as"), "expected a name without '.' or '/'");
          continue;
        }
        nested_prefix += as.get<std::string>() + "/";
      }
      json passed = json::object();
      if (entry.contains("variables")) {
        passed = substitute(entry["variables"], variables, where.child("variables"));
        if (!passed.is_object()) {
          diagnostics_.add(where.child("variables"), "expected an object of name: value");
          passed = json::object();
        }
      }
      load(included_file(dir, entry["file"].get<std::string>()), nested_prefix, passed,
           where.child("file"));
    }
  }

  // Beside the including file; failing that, among the graphs Tilth ships, so that a
  // machine's graph copied to /etc/tilth/ still includes cameras.json and the chain.
  // A name the file system refuses (too long, say) is not there: loading it then says so.
  static fs::path included_file(const fs::path& dir, const std::string& name) {
    const auto exists = [](const fs::path& file) {
      std::error_code error;
      return fs::exists(file, error);
    };
    const fs::path beside = dir / name;
    if (exists(beside) || fs::path(name).is_absolute()) return beside;
    const fs::path shipped = shipped_data_dir() / "graphs" / name;
    return exists(shipped) ? shipped : beside;
  }

  void load_nodes(const json& document, const Location& root, const fs::path& dir,
                  const std::string& prefix, const json& variables) {
    if (!document.contains("nodes")) return;
    const json& nodes = document["nodes"];
    const Location list = root.child("nodes");
    if (!nodes.is_object()) {
      diagnostics_.add(list, "expected an object of node name: {\"type\": ..., \"params\": ...}");
      return;
    }
    for (const auto& [local_name, body] : nodes.items()) {
      const Location where = list.child(local_name);
      if (local_name.empty() || local_name.find('.') != std::string::npos ||
          local_name == "runtime") {
        diagnostics_.add(where, "node names must be non-empty, without '.', and not 'runtime'");
        continue;
      }
      const std::string name = prefix + local_name;
      if (body.is_null()) {
        remove_node(name, where);
        continue;
      }
      if (!body.is_object()) {
        diagnostics_.add(where,
                         "expected {\"type\": ..., \"params\": ...}, or null to remove "
                         "an included node");
        continue;
      }
      check_keys(body, where, kNodeKeys, "node");
      NodeSpec* node = find_node(name);
      if (body.contains("type")) {
        if (!body["type"].is_string()) {
          diagnostics_.add(where.child("type"), "expected a stage type name (a string)");
          continue;
        }
        if (node == nullptr) {
          node_index_[name] = graph_.nodes.size();
          graph_.nodes.push_back({});
          node = &graph_.nodes.back();
        }
        *node = NodeSpec{name, body["type"].get<std::string>(), where, {}};
      } else if (node == nullptr) {
        diagnostics_.add(where, "node '" + name +
                                    "' has no \"type\" and overrides no included node" +
                                    did_you_mean(name, node_names()));
        continue;
      }
      if (!body.contains("params")) continue;
      const Location params_where = where.child("params");
      if (!body["params"].is_object()) {
        diagnostics_.add(params_where, "expected an object of parameter: value");
        continue;
      }
      for (const auto& [param, value] : body["params"].items()) {
        const Location param_where = params_where.child(param);
        node->params[param] = {nlohmann::json(substitute(value, variables, param_where)),
                               param_where, base_dir(value, dir), std::nullopt,
                               whole_reference(value)};
      }
    }
  }

  // An included node, every edge to or from it and the included file's inputs and outputs
  // on it leave the graph.
  void remove_node(const std::string& name, const Location& where) {
    const auto found = node_index_.find(name);
    if (found == node_index_.end()) {
      diagnostics_.add(where, "null removes an included node, but there is no node '" + name + "'" +
                                  did_you_mean(name, node_names()));
      return;
    }
    const std::size_t removed = found->second;
    graph_.nodes.erase(graph_.nodes.begin() + static_cast<std::ptrdiff_t>(removed));
    node_index_.erase(found);
    for (auto& [other, index] : node_index_) {
      if (index > removed) --index;
    }
    const auto touches = [&](const std::string& endpoint) {
      return endpoint.substr(0, endpoint.rfind('.')) == name;
    };
    std::erase_if(graph_.edges,
                  [&](const EdgeSpec& edge) { return touches(edge.from) || touches(edge.to); });
    const auto on_it = [&](const BoundaryPort& port) { return touches(port.endpoint); };
    std::erase_if(graph_.inputs, on_it);
    std::erase_if(graph_.outputs, on_it);
  }

  void load_edges(const json& document, const Location& root, const std::string& prefix) {
    if (!document.contains("edges")) return;
    const json& edges = document["edges"];
    const Location list = root.child("edges");
    if (!edges.is_array()) {
      diagnostics_.add(list, "expected an array of [\"node.port\", \"node.port\"]");
      return;
    }
    for (std::size_t i = 0; i < edges.size(); ++i) {
      const Location where = list.child(std::to_string(i));
      const json& edge = edges[i];
      json from;
      json to;
      if (edge.is_array() && edge.size() == 2) {
        from = edge[0];
        to = edge[1];
      } else if (edge.is_object() && edge.contains("from") && edge.contains("to")) {
        from = edge["from"];
        to = edge["to"];
      }
      if (!from.is_string() || !to.is_string()) {
        diagnostics_.add(where,
                         "expected [\"node.port\", \"node.port\"] or {\"from\": ..., \"to\": ...}");
        continue;
      }
      graph_.edges.push_back(
          {prefix + from.get<std::string>(), prefix + to.get<std::string>(), where});
    }
  }

  // "inputs" / "outputs": {"name": "node.port", ...}.
  void load_boundary(const json& document, const Location& root, const std::string& prefix,
                     const std::string& key, std::vector<BoundaryPort>& ports) {
    if (!document.contains(key)) return;
    const Location where = root.child(key);
    if (!document[key].is_object()) {
      diagnostics_.add(where, "expected an object of name: \"node.port\"");
      return;
    }
    for (const auto& [name, endpoint] : document[key].items()) {
      if (!endpoint.is_string()) {
        diagnostics_.add(where.child(name), "expected \"node.port\", got " + endpoint.dump());
        continue;
      }
      ports.push_back(
          {name, prefix + endpoint.get<std::string>(), where.child(name), chain_.size() == 1});
    }
  }

  void load_runtime(const json& document, const Location& root) {
    if (!document.contains("runtime")) return;
    const Location where = root.child("runtime");
    if (!document["runtime"].is_object()) {
      diagnostics_.add(where, "expected an object with max_in_flight, when_full, on_error");
      return;
    }
    check_keys(document["runtime"], where, kRuntimeKeys, "runtime");
    apply_runtime(document["runtime"], where);
  }

  void apply_runtime(const json& runtime, const Location& where) {
    for (const auto& [key, value] : runtime.items()) {
      const Location at = where.file == "command line" ? where : where.child(key);
      if (key == "max_in_flight") {
        if (value.is_number_integer() && value.get<std::int64_t>() >= 1 &&
            value.get<std::int64_t>() <= 1024) {
          graph_.runtime.max_in_flight = value.get<std::size_t>();
        } else {
          diagnostics_.add(at, "expected an integer in [1, 1024], got " + value.dump());
        }
      } else if (key == "when_full") {
        if (value == "block") {
          graph_.runtime.when_full = FullPolicy::kBlock;
        } else if (value == "drop_oldest") {
          graph_.runtime.when_full = FullPolicy::kDropOldest;
        } else {
          diagnostics_.add(at, "expected 'block' or 'drop_oldest', got " + value.dump());
        }
      } else if (key == "on_error") {
        if (value == "skip") {
          graph_.runtime.on_error = ErrorPolicy::kSkipFrame;
        } else if (value == "stop") {
          graph_.runtime.on_error = ErrorPolicy::kStop;
        } else {
          diagnostics_.add(at, "expected 'skip' or 'stop', got " + value.dump());
        }
      } else if (where.file == "command line") {
        diagnostics_.add(at,
                         "unknown runtime option '" + key + "'" + did_you_mean(key, kRuntimeKeys));
      }
    }
  }

  NodeSpec* find_node(const std::string& name) {
    const auto found = node_index_.find(name);
    return found == node_index_.end() ? nullptr : &graph_.nodes[found->second];
  }

  std::vector<std::string> node_names() const {
    std::vector<std::string> names;
    for (const auto& node : graph_.nodes) names.push_back(node.name);
    return names;
  }

  Diagnostics& diagnostics_;
  GraphSpec graph_;
  std::unordered_map<std::string, std::size_t> node_index_;  // name -> index in graph_.nodes
  std::vector<std::string> chain_;
  std::map<std::string, json> command_line_variables_;
  std::set<std::string> declared_variables_;
};

}  // namespace

Setting parse_setting(const std::string& option, const std::string& text) {
  const auto equals = text.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw Error(option + ": expected KEY=VALUE, got '" + text + "'");
  }
  return {text.substr(0, equals), text.substr(equals + 1)};
}

GraphSpec load_graph(const fs::path& file, const GraphOverrides& overrides) {
  Diagnostics diagnostics;
  Loader loader(overrides, diagnostics);
  loader.load(file, "", json::object(), Location{});
  if (diagnostics.empty()) loader.check_command_line_variables();
  if (diagnostics.empty()) loader.apply(overrides.params);
  diagnostics.throw_if_any();
  return loader.take(file);
}

}  // namespace tilth
