#include "recording_list.h"

#include <algorithm>
#include <fstream>
#include <set>

#include "image_folder/recording_json.h"
#include "tilth/error.h"

namespace tilth::ab {
namespace {

namespace fs = std::filesystem;

bool is_image_folder(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path, error) && fs::is_regular_file(path / "recording.json", error);
}

bool is_mcap(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error) && path.extension() == ".mcap";
}

// The data lines of frames.csv: the frames the source will try to replay.
std::optional<std::size_t> count_frames(const fs::path& folder) {
  std::ifstream in(folder / "frames.csv");
  if (!in) return std::nullopt;
  std::size_t lines = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) ++lines;
  }
  return lines > 0 ? lines - 1 : 0;
}

// A recording.json that cannot be read has no tags here: its replay fails, and the report
// lists that job's failure beside the other jobs' results.
std::map<std::string, std::string> tags_of(const fs::path& folder) {
  try {
    return recording::read_recording_json(folder).tags;
  } catch (const Error&) {
    return {};
  }
}

Recording make_recording(const fs::path& path) {
  const fs::path absolute = fs::absolute(path).lexically_normal();
  std::string name = is_mcap(path) ? absolute.stem().string() : absolute.filename().string();
  if (name.empty()) name = absolute.parent_path().filename().string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  if (is_mcap(path)) return {name, absolute, RecordingFormat::kMcap, std::nullopt, {}};
  return {name, absolute, RecordingFormat::kImageFolder, count_frames(absolute), tags_of(absolute)};
}

}  // namespace

std::string player_type(RecordingFormat format) {
  return format == RecordingFormat::kMcap ? "mcap.player" : "recording.image_folder";
}

std::vector<Recording> find_recordings(const std::vector<std::string>& arguments) {
  std::vector<Recording> recordings;
  for (const auto& argument : arguments) {
    const fs::path path(argument);
    std::error_code error;
    if (!fs::exists(path, error)) throw Error(argument + ": no such file or folder");
    if (is_image_folder(path) || is_mcap(path)) {
      recordings.push_back(make_recording(path));
      continue;
    }
    if (!fs::is_directory(path, error)) {
      throw Error(argument +
                  ": expected an image-folder recording (a folder with "
                  "recording.json), an .mcap file, or a folder holding them");
    }
    std::vector<fs::path> inside;
    for (const auto& entry : fs::directory_iterator(path, error)) {
      if (is_image_folder(entry.path()) || is_mcap(entry.path())) inside.push_back(entry.path());
    }
    if (inside.empty()) {
      throw Error(argument +
                  ": no recording.json, and no image-folder recording or .mcap file "
                  "directly inside");
    }
    std::sort(inside.begin(), inside.end());
    for (const auto& item : inside) recordings.push_back(make_recording(item));
  }
  // Names label report rows and folders: the second "field" becomes "field-2".
  std::set<std::string> taken;
  for (auto& recording : recordings) {
    const std::string base = recording.name;
    for (int count = 2; !taken.insert(recording.name).second; ++count) {
      recording.name = base + "-" + std::to_string(count);
    }
  }
  return recordings;
}

}  // namespace tilth::ab
