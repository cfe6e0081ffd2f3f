#include "framework/stage_registry.h"

#include <algorithm>
#include <cstdlib>
#include <set>
#include <system_error>

#include <boost/dll/shared_library.hpp>

#include "framework/install_layout.h"
#include "framework/nearest_names.h"
#include "tilth/log.h"
#include "tilth/plugin.h"

namespace tilth {
namespace {

namespace fs = std::filesystem;

constexpr const char* kDescriptorSymbol = "tilth_plugin_descriptor";

// What is wrong with a descriptor, or "".
std::string check_descriptor(const StageDescriptor& descriptor) {
  if (descriptor.type.empty() || descriptor.type.find('.') == std::string::npos) {
    return "stage type '" + descriptor.type + "' must be named 'family.stage'";
  }
  if (!descriptor.create) return "stage type '" + descriptor.type + "' has no factory";
  if (descriptor.inputs.empty() && descriptor.outputs.empty()) {
    return "stage type '" + descriptor.type + "' has no ports";
  }
  if (descriptor.input_timing == InputTiming::kOnArrival &&
      (descriptor.inputs.empty() || descriptor.outputs.empty())) {
    return "stage type '" + descriptor.type +
           "' takes its inputs on arrival (a synchronizer) and so needs inputs and outputs";
  }
  std::set<std::string> names;
  for (const auto& spec : descriptor.params) {
    if (!names.insert(spec.name).second) {
      return "stage type '" + descriptor.type + "' declares parameter '" + spec.name + "' twice";
    }
    if (!spec.default_value.is_null() && spec.type != ParamType::kJson) {
      const std::string expected = spec.check(spec.default_value);
      if (!expected.empty()) {
        return "stage type '" + descriptor.type + "': the default of parameter '" + spec.name +
               "' is " + spec.default_value.dump() + ", not " + expected;
      }
    }
  }
  return "";
}

}  // namespace

bool is_plugin_file_name(const fs::path& file) {
  const std::string name = file.filename().string();
  return name.starts_with("tilth_") && file.extension() == ".so";
}

std::vector<fs::path> plugin_search_path(const fs::path& graph_dir) {
  std::vector<fs::path> dirs;
  if (!graph_dir.empty()) dirs.push_back(graph_dir);
  if (const char* variable = std::getenv("TILTH_PLUGIN_PATH")) {
    std::string list = variable;
    std::size_t start = 0;
    while (start <= list.size()) {
      const std::size_t end = std::min(list.find(':', start), list.size());
      if (end > start) dirs.emplace_back(list.substr(start, end - start));
      start = end + 1;
    }
  }
  dirs.push_back(shipped_plugin_dir());
  return dirs;
}

namespace {

std::string text_of(const char* stamp_field) { return stamp_field ? stamp_field : "?"; }

// Refuses a plugin built on another standard library, OpenCV or nlohmann-json; notes
// another compiler.
void check_build(const std::string& name, const BuildStamp& plugin) {
  const std::pair<const char*, const char*> libraries[] = {
      {plugin.standard_library, kThisBuild.standard_library},
      {plugin.opencv, kThisBuild.opencv},
      {plugin.json, kThisBuild.json}};
  for (const auto& [theirs, ours] : libraries) {
    if (text_of(theirs) != ours) {
      throw Error(name + ": built with " + describe(plugin) + ", this runtime with " +
                  describe(kThisBuild) +
                  "; rebuild the plugin against this SDK and the same libraries (the plugin "
                  "interface passes their types)");
    }
  }
  if (text_of(plugin.compiler) != kThisBuild.compiler) {
    Logger("plugins").warning(name + ": built with " + text_of(plugin.compiler) +
                              ", this runtime with " + kThisBuild.compiler +
                              "; loaded, as both use the same libraries");
  }
}

}  // namespace

void StageRegistry::load(const fs::path& file) {
  const std::string name = file.string();
  // A name the file system refuses (over 255 bytes, from a graph's plugin list) is not
  // there either, and says why.
  std::error_code refused;
  if (!fs::exists(file, refused)) {
    throw Error(name + ": no such plugin library" +
                (refused ? " (" + refused.message() + ")" : std::string()));
  }
  auto library = std::make_shared<boost::dll::shared_library>();
  boost::dll::fs::error_code error;
  library->load(file, boost::dll::load_mode::rtld_now | boost::dll::load_mode::rtld_local, error);
  if (error) throw Error(name + ": cannot load: " + error.message());
  if (!library->has(kDescriptorSymbol)) {
    throw Error(name + ": not a Tilth plugin (it does not export " +
                std::string(kDescriptorSymbol) + "; use TILTH_PLUGIN)");
  }
  const auto* plugin = library->get<const PluginDescriptor*()>(kDescriptorSymbol)();
  if (plugin == nullptr || plugin->abi_version != kAbiVersion) {
    throw Error(name + ": built for Tilth plugin ABI " +
                (plugin ? std::to_string(plugin->abi_version) : std::string("?")) +
                ", this runtime has ABI " + std::to_string(kAbiVersion) +
                "; rebuild the plugin against this SDK");
  }
  if (plugin->size != sizeof(PluginDescriptor) || plugin->stages == nullptr) {
    throw Error(name + ": malformed plugin descriptor (size " + std::to_string(plugin->size) +
                ", expected " + std::to_string(sizeof(PluginDescriptor)) + ")");
  }
  check_build(name, plugin->build);
  // Check the whole plugin before registering any of it.
  for (const auto& descriptor : *plugin->stages) {
    if (const std::string problem = check_descriptor(descriptor); !problem.empty()) {
      throw Error(name + ": " + problem);
    }
    if (const Entry* existing = find(descriptor.type)) {
      throw Error(name + ": stage type '" + descriptor.type + "' is already provided by " +
                  existing->file.string());
    }
  }
  for (const auto& descriptor : *plugin->stages) {
    add_entry({library, descriptor, plugin->name, file});
  }
  loaded_files_.push_back(fs::weakly_canonical(file).string());
}

std::vector<std::string> StageRegistry::load_directories(const std::vector<fs::path>& dirs) {
  std::vector<std::string> problems;
  std::set<std::string> seen_names;
  for (const auto& dir : dirs) {
    std::error_code error;
    if (!fs::is_directory(dir, error)) continue;
    std::vector<fs::path> files;
    for (const auto& item : fs::directory_iterator(dir, error)) {
      if (is_plugin_file_name(item.path())) files.push_back(item.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& file : files) {
      if (!seen_names.insert(file.filename().string()).second) continue;
      const std::string canonical = fs::weakly_canonical(file).string();
      if (std::find(loaded_files_.begin(), loaded_files_.end(), canonical) != loaded_files_.end()) {
        continue;
      }
      try {
        load(file);
      } catch (const Error& failure) {
        problems.emplace_back(failure.what());
      }
    }
  }
  return problems;
}

void StageRegistry::add(StageDescriptor descriptor, const std::string& origin) {
  if (const std::string problem = check_descriptor(descriptor); !problem.empty()) {
    throw Error(origin + ": " + problem);
  }
  if (const Entry* existing = find(descriptor.type)) {
    throw Error(origin + ": stage type '" + descriptor.type + "' is already provided by " +
                existing->file.string());
  }
  add_entry({nullptr, std::move(descriptor), origin, origin});
}

void StageRegistry::add_entry(Entry entry) { entries_.push_back(std::move(entry)); }

const StageRegistry::Entry* StageRegistry::find(std::string_view type) const {
  for (const auto& entry : entries_) {
    if (entry.descriptor.type == type) return &entry;
  }
  return nullptr;
}

std::vector<std::string> StageRegistry::type_names() const {
  std::vector<std::string> names;
  for (const auto& entry : entries_) names.push_back(entry.descriptor.type);
  std::sort(names.begin(), names.end());
  return names;
}

StageInstance StageRegistry::create(std::string_view type, const StageContext& context) const {
  const Entry* entry = find(type);
  if (entry == nullptr) {
    throw Error("node '" + context.node + "': unknown stage type '" + std::string(type) + "'");
  }
  try {
    return {entry->library, entry->descriptor.create(context)};
  } catch (const std::exception& failure) {
    throw Error("node '" + context.node + "' (" + std::string(type) +
                ") failed to start: " + failure.what());
  }
}

}  // namespace tilth
