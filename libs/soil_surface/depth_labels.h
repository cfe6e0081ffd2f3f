// Pixels that label themselves by depth: residue standing clearly above the soil surface,
// soil lying on it. What a colour/texture model can be trained from without hand-drawn
// masks; the band between the two, and the edges of each, stay unlabelled.
#pragma once

#include <opencv2/core/mat.hpp>

#include "soil_surface/soil_surface.h"

namespace tilth::segmentation {

// The defaults were measured on the simulator (docs/segmentation-variants.md, labels from
// depth): 1.5 mm is three standard deviations of the 3x3-median ToF noise at 500 mm, 4 mm
// leaves 2.5 mm between the classes, and a 1 px edge drops the straws' mixed edge pixels.
struct DepthLabelOptions {
  double soil_within_mm = 1.5;    // soil: no more than this above or below the surface
  double residue_above_mm = 4.0;  // residue: more than this above it
  int edge_px = 1;                // neither within this many pixels of the other or the band
  double envelope_px = 0.0;       // the soil surface's (SoilSurface): 0 a plane, else the envelope
};

class DepthLabels {
 public:
  // Throws tilth::Error when the margins leave no band between soil and residue or are
  // not positive.
  explicit DepthLabels(const DepthLabelOptions& options);

  // `labels` (CV_8UC1, ResidueMask values): kResidue, kSoil, or kUnknown where the pixel is
  // in neither class, lies within edge_px of a pixel of the other class or the band, or has
  // no height (no depth; no soil surface found). `depth_mm` is a DepthImage's mm (CV_32FC1).
  void label(const cv::Mat& depth_mm, cv::Mat& labels) const;

 private:
  const DepthLabelOptions options_;
  const SoilSurface surface_;
  const cv::Mat edge_;  // the (2 edge_px + 1)^2 square
};

}  // namespace tilth::segmentation
