// A mask from a labelling tool turned into a residue mask's classes: each pixel's label,
// found by its colour (CVAT) or class index (LabelMe), becomes 255 (residue), 0 (soil) or
// 128 (any other label).
#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core/mat.hpp>

#include "label_map.h"

namespace tilth::tools {

// The classes (CV_8UC1) of the 8-bit PNG `file`. With a colour map the PNG may be RGB,
// RGBA (alpha ignored), palette or grey (a grey level g is the colour g,g,g); with class
// indices it is grey (the level is the index) or palette (the palette entry is the
// index), and index 255 is unknown unless a label has it. Throws tilth::Error naming the file and
// saying what was expected when it is not an 8-bit image of `size` (`size_origin` says whose size
// it is), or when a pixel has a colour or index no label has: the first such pixel, its colour and
// how many there are.
cv::Mat read_labelled_mask(const std::filesystem::path& file, const LabelMap& map, cv::Size size,
                           const std::string& size_origin);

}  // namespace tilth::tools
