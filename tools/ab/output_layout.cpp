#include "output_layout.h"

#include "tilth/error.h"

namespace tilth::ab {

namespace fs = std::filesystem;

void prepare_output(const OutputLayout& layout, bool overwrite) {
  std::error_code error;
  const bool empty = !fs::exists(layout.dir, error) || fs::is_empty(layout.dir, error);
  if (!empty) {
    if (!overwrite) {
      throw Error(layout.dir.string() +
                  ": folder exists and is not empty; give --overwrite to replace the report in it");
    }
    if (!fs::is_regular_file(layout.summary_json(), error)) {
      throw Error(layout.dir.string() +
                  ": folder holds no summary.json; not overwriting a folder that is not a report");
    }
    for (const auto& path : {layout.report(), layout.summary_json(), layout.summary_csv(),
                             layout.conditions_csv(), layout.frames_csv(), layout.runs()}) {
      fs::remove_all(path, error);
      if (error) throw Error(path.string() + ": cannot remove: " + error.message());
    }
  }
  fs::create_directories(layout.dir, error);
  if (error) throw Error(layout.dir.string() + ": cannot create the folder: " + error.message());
}

void prepare_shard_output(const OutputLayout& layout, const Shard& shard) {
  std::error_code error;
  if (fs::exists(layout.dir, error) && !fs::is_empty(layout.dir, error) &&
      !fs::is_directory(layout.shards(), error) && !fs::is_directory(layout.runs(), error)) {
    throw Error(layout.dir.string() +
                ": folder exists and holds no shard results (runs/, shards/); not writing a "
                "shard's results into it");
  }
  fs::create_directories(layout.dir, error);
  if (error) throw Error(layout.dir.string() + ": cannot create the folder: " + error.message());
  const fs::path manifest = layout.shard_manifest(shard);
  fs::remove(manifest, error);
  if (error) throw Error(manifest.string() + ": cannot remove: " + error.message());
}

}  // namespace tilth::ab
