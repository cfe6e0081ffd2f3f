// How much of a frame labels made without hand work (--labels depth) cover, and how far
// they agree with its ground-truth mask where it has one: what tilth train-segmenter
// reports per recording, and what its tests pin.
#pragma once

#include <cstdint>
#include <string>

#include <opencv2/core/mat.hpp>

#include "registered_frames.h"
#include "soil_surface/depth_labels.h"

namespace tilth::train_segmenter {

struct LabelTally {
  std::uint64_t pixels = 0;    // with trusted colour: the pixels training may draw
  std::uint64_t soil = 0;      // of those, labelled soil
  std::uint64_t residue = 0;   // labelled residue
  std::uint64_t judged = 0;    // labelled where the mask says soil or residue
  std::uint64_t agreeing = 0;  // of those, labelled as the mask says

  std::uint64_t labelled() const { return soil + residue; }
  double coverage() const;   // labelled / pixels
  double agreement() const;  // agreeing / judged
  LabelTally& operator+=(const LabelTally& other);
};

// `labels` (CV_8UC1, ResidueMask values) of `frame`, counted on its trusted pixels; judged
// is 0 when the frame has no mask.
LabelTally tally_labels(const cv::Mat& labels, const RegisteredFrame& frame);

// "depth labels 79.90 % of its pixels ... they agree with its mask on 99.97 % ..." for one
// recording.
std::string tally_text(const LabelTally& tally);

// "soil within 1.5 mm, residue above 4 mm, edge 1 px, a plane": the labels' settings.
std::string depth_labels_text(const segmentation::DepthLabelOptions& options);

}  // namespace tilth::train_segmenter
