// Residue mask in the depth image's pixel grid: 255 = residue (not soil), 0 = soil,
// 128 = unknown / ignore.
#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct ResidueMask : MessageOf<ResidueMask> {
  static constexpr std::string_view kTypeName = "tilth.ResidueMask";
  static constexpr std::uint8_t kSoil = 0;
  static constexpr std::uint8_t kUnknown = 128;
  static constexpr std::uint8_t kResidue = 255;

  cv::Mat values;  // CV_8UC1
  // The part the stage segmented (its region of interest and what it read around it);
  // every pixel outside is kUnknown. Empty: the whole image.
  cv::Rect segmented;

  std::string summary() const override;
};

}  // namespace tilth
