// The recordings a comparison replays: image-folder recordings (a folder with
// recording.json) and MCAP files, given one by one or as folders holding several.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace tilth::ab {

enum class RecordingFormat { kImageFolder, kMcap };

struct Recording {
  std::string name;  // the folder name or file stem, made unique; letters, digits, '-', '_'
  std::filesystem::path path;  // absolute
  RecordingFormat format;
  std::optional<std::size_t> frames;        // from frames.csv; unknown for MCAP until replayed
  std::map<std::string, std::string> tags;  // conditions it was recorded in: site, crop, ...
};

// The stage type that replays the format ("recording.image_folder", "mcap.player").
std::string player_type(RecordingFormat format);

// Expands the arguments in order; a folder that is not itself a recording contributes
// the recordings directly inside it, sorted by name. Throws tilth::Error naming an
// argument that is neither.
std::vector<Recording> find_recordings(const std::vector<std::string>& arguments);

}  // namespace tilth::ab
