// The stage types of the loaded plugins. Plugin libraries stay loaded while the
// registry or any stage made from it lives; they are never unloaded under a running
// graph.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "tilth/stage_descriptor.h"

namespace tilth {

// A stage together with the library its code lives in (destroyed stage first).
struct StageInstance {
  std::shared_ptr<const void> library;
  std::unique_ptr<Stage> stage;
};

class StageRegistry {
 public:
  struct Entry {
    std::shared_ptr<const void> library;  // first: outlives the descriptor's code
    StageDescriptor descriptor;
    std::string plugin;
    std::filesystem::path file;
  };

  // Loads one plugin library. Throws tilth::Error naming the file: cannot load, not a
  // Tilth plugin, ABI mismatch, a stage type another plugin already provides, or a
  // stage descriptor that contradicts itself.
  void load(const std::filesystem::path& library);

  // Loads every plugin library (tilth_*.so) in the directories; a file name found in an
  // earlier directory shadows the same name in later ones. Returns the problems (one
  // line each) instead of throwing, so one broken plugin does not hide the others.
  std::vector<std::string> load_directories(const std::vector<std::filesystem::path>& dirs);

  // Registers stage types compiled into the program itself (tests, tools).
  void add(StageDescriptor descriptor, const std::string& origin);

  const Entry* find(std::string_view type) const;
  std::vector<std::string> type_names() const;
  const std::vector<Entry>& entries() const { return entries_; }

  // Makes a stage; throws tilth::Error naming the node when the constructor throws.
  StageInstance create(std::string_view type, const StageContext& context) const;

 private:
  void add_entry(Entry entry);

  std::vector<Entry> entries_;
  std::vector<std::string> loaded_files_;
};

// Where plugins are looked for, in order: the graph file's directory (when given), each
// directory of TILTH_PLUGIN_PATH, the plugins shipped beside the executable
// (shipped_plugin_dir()).
std::vector<std::filesystem::path> plugin_search_path(const std::filesystem::path& graph_dir = {});

// A plugin file name is tilth_<name>.so.
bool is_plugin_file_name(const std::filesystem::path& file);

}  // namespace tilth
