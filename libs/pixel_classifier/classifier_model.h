// The model file of segmentation.pixel_classifier, written by tilth train-segmenter: a
// random forest or boosted trees over a versioned feature set, stored with the format
// version, the feature set and its features, and how it was trained
// (docs/segmentation-variants.md).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include <opencv2/ml.hpp>

#include "pixel_classifier/feature_set.h"
#include "pixel_classifier/tree_ensemble.h"

namespace tilth::segmentation {

inline constexpr std::string_view kClassifierFormat = "tilth-pixel-classifier/2";
// The class labels of the training responses.
inline constexpr int kSoilClass = 0;
inline constexpr int kResidueClass = 1;

struct ClassifierModel {
  FeatureSet features = FeatureSet::kTexture;
  ClassifierKind kind = ClassifierKind::kForest;
  cv::Ptr<cv::ml::DTrees> trees;  // cv::ml::RTrees or cv::ml::Boost, by `kind`
  std::string training;           // free text for people (recordings, samples, scores)
};

// "forest", "boosted"; the kind of a name, or tilth::Error listing the names.
std::string_view classifier_kind_name(ClassifierKind kind);
ClassifierKind classifier_kind_named(std::string_view name);

void write_classifier_model(const std::filesystem::path& file, const ClassifierModel& model);

// Throws tilth::Error naming the file and what was expected: a missing or unreadable
// file, another format (format 1, colour cells, included: retrain), an unknown feature
// set or features other than the set's, an unknown classifier, no trained classifier.
ClassifierModel read_classifier_model(const std::filesystem::path& file);

}  // namespace tilth::segmentation
