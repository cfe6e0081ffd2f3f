// Training segmentation.pixel_classifier's trees from a recording's labelled frames (their
// ground-truth masks, or labels made from their depth), with the library's training set
// (pixel_classifier/training_set.h), and the classifier's scores on frames with a mask.
// Only pixels whose colour is trusted and whose label is soil or residue (not mixed, not
// unlabelled) take part.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core/mat.hpp>

#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/residue_classifier.h"
#include "pixel_classifier/training_set.h"
#include "registered_frames.h"

namespace tilth::train_segmenter {

using ClassifierOptions = segmentation::ClassifierOptions;

// The library's training set, fed with registered frames.
class TrainingSet : public segmentation::TrainingSet {
 public:
  using segmentation::TrainingSet::TrainingSet;

  // Adds up to `per_class` pixels of each class of the frame's ground-truth mask, drawn
  // with `seed` (the same seed, the same pixels). Returns false when it has no mask.
  bool sample(const RegisteredFrame& frame, std::size_t per_class, std::uint64_t seed);
  // The same with `labels` (CV_8UC1, ResidueMask values, the frame's size) for the mask.
  void sample(const RegisteredFrame& frame, const cv::Mat& labels, std::size_t per_class,
              std::uint64_t seed);
};

// Pixel counts of a classifier's decisions against the truth.
struct Scores {
  std::uint64_t true_residue = 0, false_residue = 0, missed_residue = 0, true_soil = 0;

  std::uint64_t pixels() const;
  double accuracy() const;     // share of pixels classified as the truth says
  double residue_iou() const;  // |predicted and true residue| / |predicted or true residue|
  double precision() const;    // of the pixels called residue, the share that is residue
  double recall() const;       // of the residue pixels, the share called residue
  Scores& operator+=(const Scores& other);
};

// A residue mask's scores (non-zero: residue) against the truth over the trusted pixels
// (non-zero) where the truth is soil or residue.
Scores score_mask(const cv::Mat& residue, const cv::Mat& truth, const cv::Mat& trusted);

// The classifier's scores on a frame; empty when the frame has no ground-truth mask.
std::optional<Scores> score_frame(const segmentation::ResidueClassifier& classifier,
                                  const RegisteredFrame& frame);

}  // namespace tilth::train_segmenter
