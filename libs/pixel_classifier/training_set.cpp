#include "pixel_classifier/training_set.h"

#include <algorithm>
#include <iterator>
#include <random>

#include <opencv2/core.hpp>
#include <opencv2/ml.hpp>

#include "pixel_classifier/pixel_features.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::segmentation {
namespace {

std::string size_text(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

void check_fits(const cv::Mat& bgr, const cv::Mat& mask, const std::string& named) {
  if (mask.size() != bgr.size() || mask.type() != CV_8UC1) {
    throw Error(named + " is " + size_text(mask) + " (expected 8-bit, the image's " +
                size_text(bgr) + ")");
  }
}

}  // namespace

void TrainingSet::sample(const cv::Mat& bgr, const cv::Mat& trusted, const cv::Mat& labels,
                         std::size_t per_class, std::uint64_t seed,
                         const std::string& labels_named) {
  check_fits(bgr, labels, labels_named);
  check_fits(bgr, trusted, labels_named + "'s trusted-colour mask");
  thread_local cv::Mat features;
  pixel_features(features_, bgr, trusted, features);
  std::array<std::vector<int>, 2> by_class;
  for (int row = 0; row < labels.rows; ++row) {
    const auto* label = labels.ptr<std::uint8_t>(row);
    const auto* use = trusted.ptr<std::uint8_t>(row);
    for (int col = 0; col < labels.cols; ++col) {
      if (!use[col]) continue;
      if (label[col] == ResidueMask::kSoil) by_class[kSoilClass].push_back(row * labels.cols + col);
      if (label[col] == ResidueMask::kResidue) {
        by_class[kResidueClass].push_back(row * labels.cols + col);
      }
    }
  }
  std::mt19937_64 rng(seed);
  for (int label : {kSoilClass, kResidueClass}) {
    std::vector<int> drawn;
    std::sample(by_class[label].begin(), by_class[label].end(), std::back_inserter(drawn),
                per_class, rng);
    for (const int pixel : drawn) samples_.push_back(features.row(pixel));
    labels_.insert(labels_.end(), drawn.size(), label);
    counts_[label] += drawn.size();
  }
}

void TrainingSet::add(const TrainingSet& other) {
  if (other.features_ != features_) throw Error("training sets of two feature sets");
  if (other.samples_.empty()) return;
  samples_.push_back(other.samples_);
  labels_.insert(labels_.end(), other.labels_.begin(), other.labels_.end());
  counts_[0] += other.counts_[0];
  counts_[1] += other.counts_[1];
}

ClassifierModel TrainingSet::train(const ClassifierOptions& options,
                                   const std::string& training) const {
  if (soil() == 0 || residue() == 0) {
    throw Error("the training frames show " + std::to_string(soil()) + " soil and " +
                std::to_string(residue()) +
                " residue pixels (expected both classes among their labelled pixels)");
  }
  const cv::Mat responses(labels_, true);
  cv::Mat weights(static_cast<int>(labels_.size()), 1, CV_32F);
  const double all = static_cast<double>(labels_.size());
  for (std::size_t i = 0; i < labels_.size(); ++i) {
    weights.at<float>(static_cast<int>(i)) = static_cast<float>(all / (2.0 * counts_[labels_[i]]));
  }
  // Integer responses: OpenCV takes the labels as classes.
  const auto data = cv::ml::TrainData::create(samples_, cv::ml::ROW_SAMPLE, responses,
                                              cv::noArray(), cv::noArray(), weights);
  ClassifierModel model;
  model.features = features_;
  model.kind = options.kind;
  model.training = training;
  if (options.kind == ClassifierKind::kForest) {
    cv::Ptr<cv::ml::RTrees> forest = cv::ml::RTrees::create();
    forest->setMaxDepth(options.depth);
    forest->setMinSampleCount(5);
    forest->setTermCriteria({cv::TermCriteria::MAX_ITER, options.trees, 0});
    model.trees = forest;
  } else {
    cv::Ptr<cv::ml::Boost> boost = cv::ml::Boost::create();
    boost->setBoostType(cv::ml::Boost::REAL);
    boost->setWeakCount(options.trees);
    boost->setMaxDepth(options.depth);
    boost->setMinSampleCount(5);
    boost->setUseSurrogates(false);
    model.trees = boost;
  }
  // OpenCV draws from the calling thread's theRNG(): seeded, the same samples give the
  // same trees whatever was trained before.
  cv::theRNG() = cv::RNG(options.seed);
  model.trees->train(data);
  return model;
}

}  // namespace tilth::segmentation
