// Training segmentation.pixel_classifier's trees from frames with ground-truth masks:
// pixels sampled per frame and class, the classifier, and its scores on labelled frames.
// Only pixels whose colour is trusted and whose truth is soil or residue (not mixed)
// take part.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/residue_classifier.h"
#include "registered_frames.h"

namespace tilth::train_segmenter {

struct ClassifierOptions {
  segmentation::ClassifierKind kind = segmentation::ClassifierKind::kForest;
  int trees = 5;           // trees of a forest, weak trees of boosting
  int depth = 6;           // deepest level of a tree
  std::uint64_t seed = 1;  // of OpenCV's draws (bootstrap samples, features tried per split)
};

class TrainingSet {
 public:
  explicit TrainingSet(segmentation::FeatureSet features) : features_(features) {}

  // Adds up to `per_class` pixels of each class of the frame, drawn with `seed` (the same
  // seed, the same pixels). Returns false when the frame has no ground-truth mask.
  bool sample(const RegisteredFrame& frame, std::size_t per_class, std::uint64_t seed);
  // Adds another set's samples (of the same feature set).
  void add(const TrainingSet& other);

  segmentation::FeatureSet features() const { return features_; }
  std::size_t soil() const { return counts_[0]; }
  std::size_t residue() const { return counts_[1]; }

  // The classifier of `options` on the samples, the classes weighted equally (each sample
  // by all samples / (2 x its class's samples)). Throws tilth::Error when a class has no
  // samples.
  segmentation::ClassifierModel train(const ClassifierOptions& options,
                                      const std::string& training) const;

 private:
  segmentation::FeatureSet features_;
  cv::Mat samples_;  // one row of features per sample
  std::vector<std::int32_t> labels_;
  std::array<std::size_t, 2> counts_{};
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

// The classifier's scores on a frame; empty when the frame has no ground-truth mask.
std::optional<Scores> score_frame(const segmentation::ResidueClassifier& classifier,
                                  const RegisteredFrame& frame);

}  // namespace tilth::train_segmenter
