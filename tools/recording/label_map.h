// The labels of a labelling tool's mask export, and which of them are residue and which
// soil: CVAT's labelmap.txt (each label's colour) or LabelMe's label_names.txt (each
// label's class index), read from the export's folder.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/matx.hpp>

namespace tilth::tools {

struct Label {
  std::string name;
  std::optional<cv::Vec3b> rgb;   // CVAT: the label's colour in the masks
  std::uint8_t mask_value = 128;  // 255 residue, 0 soil, 128 unknown (assign_classes)
};

struct LabelMap {
  enum class Encoding { kColor, kIndex };

  std::filesystem::path file;  // labelmap.txt, label_names.txt or class_names.txt
  Encoding encoding = Encoding::kColor;
  std::vector<Label> labels;  // kIndex: a label's position is its class index

  // "straw, stubble, soil"
  std::string names() const;
};

// FOLDER/labelmap.txt (CVAT, "Segmentation mask 1.1": `name:r,g,b:parts:actions` lines,
// `#` comments), or FOLDER/label_names.txt or class_names.txt (LabelMe: one name a line,
// the first is class 0). Throws tilth::Error naming the file and line for a malformed
// line, a name or colour twice, more than 256 indexed labels, or when the folder holds
// none of the files or more than one.
LabelMap read_label_map(const std::filesystem::path& folder);

// Each label's mask value: 255 for the names in `residue`, 0 for those in `soil`, 128 for
// the rest. Throws tilth::Error for a name the map does not have (with the nearest ones)
// or one in both lists.
void assign_classes(LabelMap& map, const std::vector<std::string>& residue,
                    const std::vector<std::string>& soil);

}  // namespace tilth::tools
