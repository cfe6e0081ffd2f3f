// What is known to be true about a frame, from a simulator or a labelled recording:
// the ground distance and the residue mask, each when known.
#pragma once

#include <optional>

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct GroundTruth : MessageOf<GroundTruth> {
  static constexpr std::string_view kTypeName = "tilth.GroundTruth";

  // Mounting surface to soil along the optical axis, as GroundDistance::distance_mm.
  std::optional<double> distance_mm;
  // In the depth grid, values as ResidueMask (255 residue, 0 soil, 128 unknown); empty
  // when unknown.
  cv::Mat residue_mask;

  std::string summary() const override;
};

}  // namespace tilth
