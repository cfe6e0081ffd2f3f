// Training a pixel classifier's trees from labelled images (ground-truth masks, or labels
// made from depth): pixels sampled per image and class, and the classifier trained on them.
// tilth train-segmenter and segmentation.self_trained both train with it. Only pixels whose
// colour is trusted and whose label is soil or residue (not mixed, not unlabelled) take part.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "pixel_classifier/classifier_model.h"

namespace tilth::segmentation {

struct ClassifierOptions {
  ClassifierKind kind = ClassifierKind::kForest;
  int trees = 5;           // trees of a forest, weak trees of boosting
  int depth = 6;           // deepest level of a tree
  std::uint64_t seed = 1;  // of OpenCV's draws (bootstrap samples, features tried per split)
};

class TrainingSet {
 public:
  explicit TrainingSet(FeatureSet features) : features_(features) {}

  // Adds up to `per_class` pixels of each class of `labels` (CV_8UC1, ResidueMask values)
  // among the `trusted` pixels (CV_8UC1, non-zero: the colour may be used) of a CV_8UC3 BGR
  // image, drawn with `seed` (the same seed, the same pixels). The features are the
  // image's (pixel_features, normalised over its trusted pixels). `labels_named` names the
  // labels in errors ("frame 12: the ground-truth mask"). Throws tilth::Error when `labels`
  // or `trusted` is not 8-bit of the image's size.
  void sample(const cv::Mat& bgr, const cv::Mat& trusted, const cv::Mat& labels,
              std::size_t per_class, std::uint64_t seed, const std::string& labels_named);
  // Adds another set's samples (of the same feature set).
  void add(const TrainingSet& other);

  FeatureSet features() const { return features_; }
  std::size_t soil() const { return counts_[0]; }
  std::size_t residue() const { return counts_[1]; }

  // The classifier of `options` on the samples, the classes weighted equally (each sample
  // by all samples / (2 x its class's samples)); `training` is the model's free text.
  // Throws tilth::Error when a class has no samples. OpenCV draws from the calling
  // thread's cv::theRNG(), which this seeds with options.seed.
  ClassifierModel train(const ClassifierOptions& options, const std::string& training) const;

 private:
  FeatureSet features_;
  cv::Mat samples_;  // one row of features per sample
  std::vector<std::int32_t> labels_;
  std::array<std::size_t, 2> counts_{};
};

}  // namespace tilth::segmentation
