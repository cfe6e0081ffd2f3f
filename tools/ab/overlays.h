// The frames of a recording where the variants disagree most, as side-by-side mask
// overlays: the colour on the depth grid, the truth mask, and each variant's mask
// coloured against the truth.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "comparison.h"

namespace tilth::ab {

struct OverlayPanel {
  std::string caption;
  std::string data_uri;  // empty when the image is not there
};

struct OverlayFrame {
  std::uint64_t frame_id = 0;
  std::string reason;  // "valid in 1 of 2 variants", "distances 2.104 mm apart"
  std::vector<OverlayPanel> panels;
};

// Frames ranked by: validity differs between variants, then the spread of the valid
// distances, then the largest |error|; ties go to the earlier frame. Reads the images
// the evaluation sinks saved (JobResult::images).
std::vector<OverlayFrame> disagreement_overlays(const Comparison& comparison, std::size_t recording,
                                                std::size_t count);

}  // namespace tilth::ab
