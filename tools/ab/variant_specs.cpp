// Variants file:
//   {"chain": "measurement-chain.json",                       (optional, for every variant)
//    "variants": [
//      {"name": "threshold", "description": "the paper's colour threshold"},
//      {"name": "wide", "set": {"segment.dilation_px": 4}},
//      {"name": "plane", "set": {"estimate.type": "estimation.ground_plane",
//                                "estimate.calibration": "../../calib/paper_rig.calib.json"}},
//      {"name": "mine", "chain": "my-chain.json", "ports": {"mask": null}}]}
// Paths are relative to the variants file.
#include "variant_specs.h"

#include <algorithm>

#include "framework/diagnostics.h"
#include "framework/nearest_names.h"
#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

const std::vector<std::string> kFileKeys = {"chain", "variants"};
const std::vector<std::string> kVariantKeys = {"name",  "description", "chain",
                                               "ports", "set",         "recorded"};
const std::vector<std::string> kPortKeys = {"raw", "color", "distance", "mask", "registered_color"};

Variant* find_variant(std::vector<Variant>& variants, const std::string& name) {
  for (auto& variant : variants) {
    if (variant.name == name) return &variant;
  }
  return nullptr;
}

// "segment.dilation_px" -> {"segment", "dilation_px"}; empty when malformed.
std::pair<std::string, std::string> split_node_key(const std::string& key) {
  const auto dot = key.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == key.size()) return {};
  return {key.substr(0, dot), key.substr(dot + 1)};
}

// JSON, or the text itself when it is not JSON (as --set); JSON that is refused (a
// duplicate key, a number beyond double range) is an error.
nlohmann::json parse_json_or_text(const std::string& text, const std::string& where) {
  try {
    return parse_json(text, where);
  } catch (const JsonError& error) {
    if (error.malformed()) return text;
    throw;
  }
}

fs::path absolute_from(const fs::path& base, const std::string& path) {
  return (base / path).lexically_normal();
}

class FileReader {
 public:
  FileReader(const fs::path& file, const fs::path& default_chain)
      : file_(file.string()), dir_(fs::absolute(file).parent_path()), chain_(default_chain) {}

  void read(std::vector<Variant>& variants) {
    const Location root{file_, ""};
    json document;
    try {
      document =
          parse_ordered_json(read_json_text(file_, "the variants file"), file_, {.comments = true});
    } catch (const JsonError& error) {
      problems_.add({file_, error.pointer(), error.line(), error.column()},
                    (error.malformed() ? "malformed JSON: " : "") + error.reason());
      problems_.throw_if_any();
    }
    if (!document.is_object() || !document.contains("variants") ||
        !document["variants"].is_array()) {
      problems_.add(root, "expected an object with \"variants\": [{\"name\": ...}, ...]");
      problems_.throw_if_any();
    }
    check_keys(document, root, kFileKeys, "variants file");
    if (document.contains("chain")) chain_ = read_chain(document["chain"], root.child("chain"));
    const auto& list = document["variants"];
    for (std::size_t i = 0; i < list.size(); ++i) {
      read_variant(list[i], root.child("variants").child(std::to_string(i)), variants);
    }
    problems_.throw_if_any();
  }

 private:
  void read_variant(const json& entry, const Location& where, std::vector<Variant>& variants) {
    if (!entry.is_object() || !entry.contains("name") || !entry["name"].is_string()) {
      problems_.add(where, "expected {\"name\": NAME, \"set\": {...}, ...}");
      return;
    }
    check_keys(entry, where, kVariantKeys, "variant");
    Variant variant;
    variant.name = entry["name"].get<std::string>();
    try {
      check_variant_name(variant.name, where.child("name").text());
    } catch (const Error& error) {
      problems_.add(where.child("name"), error.what());
      return;
    }
    if (find_variant(variants, variant.name) != nullptr) {
      problems_.add(where.child("name"), "variant '" + variant.name + "' is defined twice");
      return;
    }
    if (entry.contains("description")) {
      if (entry["description"].is_string()) {
        variant.description = entry["description"].get<std::string>();
      } else {
        problems_.add(where.child("description"), "expected a string");
      }
    }
    variant.chain = chain_;
    variant.chain_where = Location{file_, where.pointer};
    if (entry.contains("chain")) {
      variant.chain = read_chain(entry["chain"], where.child("chain"));
      variant.chain_where = where.child("chain");
    }
    if (entry.contains("ports")) read_ports(entry["ports"], where.child("ports"), variant.ports);
    if (entry.contains("set")) read_settings(entry["set"], where.child("set"), variant.settings);
    if (entry.contains("recorded")) {
      if (!entry["recorded"].is_boolean()) {
        problems_.add(where.child("recorded"), "expected true or false");
      } else if (entry["recorded"].get<bool>()) {
        variant.recorded = true;
        for (const char* key : {"chain", "ports", "set"}) {
          if (entry.contains(key)) {
            problems_.add(where.child(key), "a recorded variant runs no chain: no '" +
                                                std::string(key) + "' with \"recorded\": true");
          }
        }
      }
    }
    variants.push_back(std::move(variant));
  }

  fs::path read_chain(const json& value, const Location& where) {
    if (!value.is_string() || value.get<std::string>().empty()) {
      problems_.add(where, "expected the path of a chain graph file");
      return chain_;
    }
    const fs::path chain = absolute_from(dir_, value.get<std::string>());
    if (!fs::is_regular_file(chain)) problems_.add(where, "no such file: " + chain.string());
    return chain;
  }

  void read_ports(const json& ports, const Location& where, ChainPorts& result) {
    if (!ports.is_object()) {
      problems_.add(where, "expected an object of port: \"node.port\"");
      return;
    }
    check_keys(ports, where, kPortKeys, "ports");
    const auto endpoint = [&](const std::string& key, bool optional) -> std::optional<std::string> {
      const json& value = ports[key];
      if (optional && value.is_null()) return std::nullopt;
      if (!value.is_string() || split_node_key(value.get<std::string>()).first.empty()) {
        problems_.add(where.child(key), std::string("expected \"node.port\" of the chain") +
                                            (optional ? " or null" : ""));
        return std::nullopt;
      }
      return value.get<std::string>();
    };
    if (ports.contains("raw")) result.raw = endpoint("raw", false).value_or(result.raw);
    if (ports.contains("color")) result.color = endpoint("color", false).value_or(result.color);
    if (ports.contains("distance")) {
      result.distance = endpoint("distance", false).value_or(result.distance);
    }
    result.optional_ports_named = ports.contains("mask") || ports.contains("registered_color");
    if (ports.contains("mask")) result.mask = endpoint("mask", true);
    if (ports.contains("registered_color")) {
      result.registered_color = endpoint("registered_color", true);
    }
  }

  void read_settings(const json& set, const Location& where, std::vector<NodeSetting>& settings) {
    if (!set.is_object()) {
      problems_.add(where, "expected an object of \"node.param\": value");
      return;
    }
    for (const auto& [key, value] : set.items()) {
      const auto [node, param] = split_node_key(key);
      if (node.empty()) {
        problems_.add(where.child(key), "expected a key \"NODE.PARAM\" or \"NODE.type\"");
        continue;
      }
      settings.push_back({node, param, value, std::nullopt, dir_, where.child(key)});
    }
  }

  void check_keys(const json& object, const Location& where, const std::vector<std::string>& known,
                  const std::string& what) {
    for (const auto& [key, value] : object.items()) {
      if (std::find(known.begin(), known.end(), key) == known.end()) {
        problems_.add(where.child(key), "unknown key '" + key + "' in " + what +
                                            did_you_mean(key, known) + " (expected one of " +
                                            quoted_list(known) + ")");
      }
    }
  }

  const std::string file_;
  const fs::path dir_;
  fs::path chain_;
  Diagnostics problems_;
};

}  // namespace

void add_variants_from_file(const fs::path& file, const fs::path& default_chain,
                            std::vector<Variant>& variants) {
  FileReader(file, default_chain).read(variants);
}

void add_variant_option(const std::string& option, const fs::path& default_chain,
                        std::vector<Variant>& variants) {
  const std::string where = "--variant " + option;
  const auto colon = option.find(':');
  const std::string name = option.substr(0, colon);
  check_variant_name(name, where);
  Variant* variant = find_variant(variants, name);
  if (variant == nullptr) {
    variants.push_back({name, "", default_chain, Location{"command line", where}, {}, {}, false});
    variant = &variants.back();
  }
  if (colon == std::string::npos) return;
  const std::string setting = option.substr(colon + 1);
  if (setting == "recorded") {
    variant->recorded = true;
    return;
  }
  const auto equals = setting.find('=');
  if (equals == std::string::npos) {
    throw Error(where +
                ": expected NAME:chain=FILE, NAME:NODE.type=STAGE_TYPE, NAME:NODE.PARAM=VALUE "
                "or NAME:recorded");
  }
  const std::string key = setting.substr(0, equals);
  const std::string value = setting.substr(equals + 1);
  if (key == "chain") {
    const fs::path chain = fs::absolute(value).lexically_normal();
    if (value.empty() || !fs::is_regular_file(chain)) {
      throw Error(where + ": expected the path of a chain graph file; no such file: " + value);
    }
    variant->chain = chain;
    variant->chain_where = Location{"command line", where};
    return;
  }
  const auto [node, param] = split_node_key(key);
  if (node.empty()) {
    throw Error(where + ": expected NODE.PARAM=VALUE or NODE.type=STAGE_TYPE, got key '" + key +
                "'");
  }
  variant->settings.push_back({node, param, parse_json_or_text(value, where), value,
                               fs::current_path(), Location{"command line", where}});
}

}  // namespace tilth::ab
