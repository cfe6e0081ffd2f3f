// The palette of a palette PNG (colour type 3), read from the file's PLTE chunk: OpenCV
// decodes such a PNG to colours, and a mask whose pixels are class indices (LabelMe's
// label PNG) needs the palette to turn them back into indices.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/matx.hpp>

namespace tilth::tools {

// The palette's entries as r, g, b, in index order; empty when `png` (a PNG file's bytes)
// is not a palette PNG (colour type 3) with a PLTE chunk before its image data.
std::vector<cv::Vec3b> png_palette(const std::string& png);

}  // namespace tilth::tools
