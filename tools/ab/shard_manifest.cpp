#include "shard_manifest.h"

#include <algorithm>

#include "report_numbers.h"
#include "tilth/json_input.h"
#include "tilth/version.h"

namespace tilth::ab {

namespace fs = std::filesystem;
using nlohmann::ordered_json;

namespace {

ShardManifest manifest_from(const fs::path& file, const ordered_json& document) {
  ShardManifest manifest;
  manifest.file = file;
  try {
    manifest.shard = parse_shard(std::to_string(document.at("shard").get<std::size_t>()) + "/" +
                                 std::to_string(document.at("shards").get<std::size_t>()));
    manifest.version = document.at("version").get<std::string>();
    manifest.working_directory = document.at("working_directory").get<std::string>();
    manifest.arguments = document.at("arguments").get<std::vector<std::string>>();
    manifest.comparison = document.at("comparison");
    manifest.jobs = document.at("jobs").get<std::vector<std::size_t>>();
  } catch (const nlohmann::json::exception& error) {
    throw Error(file.string() + ": not a shard manifest of tilth ab: " + error.what());
  } catch (const Error& error) {
    throw Error(file.string() + ": " + error.what());
  }
  return manifest;
}

}  // namespace

ordered_json comparison_identity(const Options& options) {
  ordered_json variables = ordered_json::array();
  for (const Setting& variable : options.variables.variables) {
    variables.push_back(variable.key + "=" + variable.value);
  }
  return {{"variants", variants_json(options.variants)},
          {"baseline", options.variants.at(options.baseline).name},
          {"recordings", recordings_json(options.recordings)},
          {"variables", variables},
          {"no_soil_below", options.no_soil_below},
          {"overlays", options.overlays}};
}

void write_shard_manifest(const OutputLayout& layout, const ShardManifest& manifest) {
  const ordered_json document = {{"shard", manifest.shard.index},
                                 {"shards", manifest.shard.count},
                                 {"version", manifest.version},
                                 {"working_directory", manifest.working_directory.string()},
                                 {"arguments", manifest.arguments},
                                 {"comparison", manifest.comparison},
                                 {"jobs", manifest.jobs}};
  std::error_code error;
  fs::create_directories(layout.shards(), error);
  if (error)
    throw Error(layout.shards().string() + ": cannot create the folder: " + error.message());
  const fs::path file = layout.shard_manifest(manifest.shard);
  const fs::path partial = file.string() + ".partial";
  write_text(partial, document.dump(2) + "\n");
  fs::rename(partial, file, error);
  if (error) throw Error(file.string() + ": cannot write the file: " + error.message());
}

std::vector<ShardManifest> read_shard_manifests(const OutputLayout& layout) {
  std::vector<fs::path> files;
  std::error_code error;
  if (fs::is_directory(layout.shards(), error)) {
    for (const auto& entry : fs::directory_iterator(layout.shards())) {
      if (entry.path().extension() == ".json") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  std::vector<ShardManifest> manifests;
  for (const auto& file : files) {
    const std::string origin = file.string();
    manifests.push_back(
        manifest_from(file, parse_ordered_json(read_json_text(file, "shard manifest"), origin)));
  }
  return manifests;
}

}  // namespace tilth::ab
