#include "output_path.h"

#include <algorithm>
#include <array>
#include <fstream>

#include "tilth/error.h"

namespace tilth::tools {
namespace {

namespace fs = std::filesystem;

bool is_mcap_file(const fs::path& file) {
  if (!fs::is_regular_file(file)) return false;
  if (fs::file_size(file) == 0) return true;
  constexpr std::array<char, 8> kMagic{'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  std::array<char, 8> start{};
  std::ifstream in(file, std::ios::binary);
  in.read(start.data(), start.size());
  return in && start == kMagic;
}

bool is_image_folder(const fs::path& folder) {
  return fs::is_directory(folder) && fs::is_regular_file(folder / "recording.json");
}

// True when `inner` is `outer` or lies inside it.
bool within(const fs::path& inner, const fs::path& outer) {
  const auto [outer_end, inner_end] =
      std::mismatch(outer.begin(), outer.end(), inner.begin(), inner.end());
  return outer_end == outer.end() || (std::next(outer_end) == outer.end() && outer_end->empty());
}

}  // namespace

void check_output_path(const fs::path& output, RecordingKind kind, bool overwrite) {
  if (!fs::exists(output)) return;
  if (fs::is_directory(output) && fs::is_empty(output)) return;
  if (!overwrite) {
    throw Error(output.string() + ": exists" +
                (fs::is_directory(output) ? " and is not empty" : "") +
                "; use --overwrite to replace it");
  }
  if (kind == RecordingKind::kMcapFile && !is_mcap_file(output)) {
    throw Error(output.string() +
                ": exists and is not an MCAP file (it does not start with the MCAP magic "
                "bytes); --overwrite replaces only a recording");
  }
  if (kind == RecordingKind::kImageFolder && !is_image_folder(output)) {
    throw Error(output.string() +
                ": exists and is not an image-folder recording (no recording.json); "
                "--overwrite replaces only a recording");
  }
}

void check_apart(const fs::path& input, const fs::path& output) {
  const fs::path in = fs::weakly_canonical(fs::absolute(input));
  const fs::path out = fs::weakly_canonical(fs::absolute(output));
  std::error_code ignored;
  if (in == out || fs::equivalent(input, output, ignored)) {
    throw Error(output.string() + ": is the input " + input.string() +
                "; expected an output apart from it");
  }
  if (within(in, out)) {
    throw Error(output.string() + ": holds the input " + input.string() +
                "; expected an output apart from it");
  }
  if (within(out, in)) {
    throw Error(output.string() + ": lies inside the input " + input.string() +
                "; expected an output apart from it");
  }
}

}  // namespace tilth::tools
