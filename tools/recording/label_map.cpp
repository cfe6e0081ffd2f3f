#include "label_map.h"

#include <charconv>
#include <set>
#include <string_view>

#include "framework/nearest_names.h"
#include "image_folder/text_lines.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::tools {
namespace {

namespace fs = std::filesystem;

// A label file is a short list; lines of a few names and numbers.
constexpr recording::TextLines::Limits kLimits{1 << 20, 4096};
// A class index is a byte of an 8-bit PNG.
constexpr std::size_t kMaxIndexedLabels = 256;

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  for (;;) {
    const auto at = text.find(separator);
    parts.push_back(text.substr(0, at));
    if (at == std::string_view::npos) return parts;
    text.remove_prefix(at + 1);
  }
}

std::string rgb_text(const cv::Vec3b& rgb) {
  return std::to_string(rgb[0]) + "," + std::to_string(rgb[1]) + "," + std::to_string(rgb[2]);
}

std::optional<cv::Vec3b> parse_rgb(std::string_view text) {
  const auto parts = split(text, ',');
  if (parts.size() != 3) return std::nullopt;
  cv::Vec3b rgb;
  for (int i = 0; i < 3; ++i) {
    const std::string_view part = parts[static_cast<std::size_t>(i)];
    int value = -1;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (part.empty() || error != std::errc() || end != part.data() + part.size() || value < 0 ||
        value > 255) {
      return std::nullopt;
    }
    rgb[i] = static_cast<std::uint8_t>(value);
  }
  return rgb;
}

// CVAT's "Segmentation mask 1.1" label map, e.g. "straw:250,50,83::".
LabelMap read_cvat(const fs::path& file) {
  LabelMap map{file, LabelMap::Encoding::kColor, {}};
  recording::TextLines lines(file, kLimits, "labelmap.txt");
  std::string_view line;
  while (lines.next(line)) {
    const std::string where = file.string() + ":" + std::to_string(lines.number()) + ": ";
    if (line.empty() || line.front() == '#') continue;
    const auto fields = split(line, ':');
    const std::optional<cv::Vec3b> rgb =
        fields.size() >= 2 ? parse_rgb(fields[1]) : std::optional<cv::Vec3b>();
    if (fields[0].empty() || !rgb) {
      throw Error(where + "expected 'label:r,g,b:parts:actions' with r, g, b from 0 to 255, got '" +
                  std::string(line) + "'");
    }
    for (const Label& known : map.labels) {
      if (known.name == fields[0]) throw Error(where + "label '" + known.name + "' appears twice");
      if (known.rgb == rgb) {
        throw Error(where + "label '" + std::string(fields[0]) + "' has the colour " +
                    rgb_text(*rgb) + " of label '" + known.name +
                    "'; expected a colour of its own, or the masks cannot tell them apart");
      }
    }
    map.labels.push_back({std::string(fields[0]), rgb});
  }
  if (map.labels.empty()) throw Error(file.string() + ": names no label; expected at least one");
  return map;
}

// LabelMe's label names: line N is class index N - 1.
LabelMap read_labelme(const fs::path& file) {
  LabelMap map{file, LabelMap::Encoding::kIndex, {}};
  recording::TextLines lines(file, kLimits, file.filename().string());
  std::string_view line;
  while (lines.next(line)) {
    const std::string where = file.string() + ":" + std::to_string(lines.number()) + ": ";
    if (line.empty())
      throw Error(where + "expected a label name (class index " +
                  std::to_string(map.labels.size()) + "), got an empty line");
    for (const Label& known : map.labels) {
      if (known.name == line) throw Error(where + "label '" + known.name + "' appears twice");
    }
    if (map.labels.size() == kMaxIndexedLabels) {
      throw Error(where + "more than " + std::to_string(kMaxIndexedLabels) +
                  " labels; expected at most that many (class indices of an 8-bit PNG)");
    }
    map.labels.push_back({std::string(line), std::nullopt});
  }
  if (map.labels.empty()) throw Error(file.string() + ": names no label; expected at least one");
  return map;
}

std::vector<std::string> names_of(const LabelMap& map) {
  std::vector<std::string> names;
  for (const Label& label : map.labels) names.push_back(label.name);
  return names;
}

}  // namespace

std::string LabelMap::names() const {
  std::string text;
  for (const Label& label : labels) text += (text.empty() ? "" : ", ") + label.name;
  return text;
}

LabelMap read_label_map(const fs::path& folder) {
  std::vector<fs::path> found;
  for (const char* name : {"labelmap.txt", "label_names.txt", "class_names.txt"}) {
    if (fs::exists(folder / name)) found.push_back(folder / name);
  }
  if (found.empty()) {
    throw Error(folder.string() +
                ": holds no labelmap.txt (CVAT, Segmentation mask 1.1) and no label_names.txt "
                "or class_names.txt (LabelMe); expected the label names of the masks");
  }
  if (found.size() > 1) {
    throw Error(folder.string() + ": holds both " + found[0].filename().string() + " and " +
                found[1].filename().string() + "; expected the label names of one export");
  }
  return found[0].filename() == "labelmap.txt" ? read_cvat(found[0]) : read_labelme(found[0]);
}

void assign_classes(LabelMap& map, const std::vector<std::string>& residue,
                    const std::vector<std::string>& soil) {
  const std::vector<std::string> known = names_of(map);
  const auto check = [&](const std::string& name, const char* option) {
    for (const std::string& label : known) {
      if (label == name) return;
    }
    throw Error(std::string(option) + ": no label '" + name + "' in " + map.file.string() +
                did_you_mean(name, known) + " (labels: " + map.names() + ")");
  };
  const std::set<std::string> residue_names(residue.begin(), residue.end());
  for (const std::string& name : residue) check(name, "--residue");
  for (const std::string& name : soil) {
    check(name, "--soil");
    if (residue_names.count(name) != 0) {
      throw Error("label '" + name + "' is in both --residue and --soil; expected one class");
    }
  }
  const std::set<std::string> soil_names(soil.begin(), soil.end());
  for (Label& label : map.labels) {
    label.mask_value = residue_names.count(label.name) != 0 ? ResidueMask::kResidue
                       : soil_names.count(label.name) != 0  ? ResidueMask::kSoil
                                                            : ResidueMask::kUnknown;
  }
}

}  // namespace tilth::tools
