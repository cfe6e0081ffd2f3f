// How much of a frame labels made without hand work (--labels depth) cover, and how far
// they agree with its ground-truth mask where it has one: what tilth train-segmenter
// reports per recording, and what its tests pin.
#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

#include "registered_frames.h"

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

}  // namespace tilth::train_segmenter
