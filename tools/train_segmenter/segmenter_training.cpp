#include "segmenter_training.h"

#include <algorithm>
#include <random>

#include "pixel_classifier/pixel_features.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::train_segmenter {
namespace {

using segmentation::kResidueClass;
using segmentation::kSoilClass;

// The frame's features (pixel_features, normalised over its trusted pixels, as the stage
// does) and which pixels take part; false when the frame has no ground-truth mask.
bool labelled_pixels(const RegisteredFrame& frame, cv::Mat& trusted) {
  const cv::Mat& truth = frame.truth->residue_mask;
  if (truth.empty()) return false;
  if (truth.size() != frame.color->bgr.size() || truth.type() != CV_8UC1) {
    throw Error("frame " + std::to_string(frame.frame_id) + ": the ground-truth mask is " +
                std::to_string(truth.cols) + "x" + std::to_string(truth.rows) +
                " (expected 8-bit, the depth image's " + std::to_string(frame.color->bgr.cols) +
                "x" + std::to_string(frame.color->bgr.rows) + ")");
  }
  trusted = frame.color->status == RegisteredColor::kValid;
  return true;
}

double ratio(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

}  // namespace

bool TrainingSet::sample(const RegisteredFrame& frame, std::size_t per_class, std::uint64_t seed) {
  thread_local cv::Mat trusted, features;
  if (!labelled_pixels(frame, trusted)) return false;
  segmentation::pixel_features(features_, frame.color->bgr, trusted, features);
  const cv::Mat& truth = frame.truth->residue_mask;
  std::array<std::vector<int>, 2> by_class;
  for (int row = 0; row < truth.rows; ++row) {
    const auto* label = truth.ptr<std::uint8_t>(row);
    const auto* use = trusted.ptr<std::uint8_t>(row);
    for (int col = 0; col < truth.cols; ++col) {
      if (!use[col]) continue;
      if (label[col] == ResidueMask::kSoil) by_class[kSoilClass].push_back(row * truth.cols + col);
      if (label[col] == ResidueMask::kResidue) {
        by_class[kResidueClass].push_back(row * truth.cols + col);
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
  return true;
}

void TrainingSet::add(const TrainingSet& other) {
  if (other.features_ != features_) throw Error("training sets of two feature sets");
  if (other.samples_.empty()) return;
  samples_.push_back(other.samples_);
  labels_.insert(labels_.end(), other.labels_.begin(), other.labels_.end());
  counts_[0] += other.counts_[0];
  counts_[1] += other.counts_[1];
}

segmentation::ClassifierModel TrainingSet::train(const ClassifierOptions& options,
                                                 const std::string& training) const {
  if (soil() == 0 || residue() == 0) {
    throw Error("the training frames show " + std::to_string(soil()) + " soil and " +
                std::to_string(residue()) +
                " residue pixels (expected both classes in the ground-truth masks)");
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
  segmentation::ClassifierModel model;
  model.features = features_;
  model.kind = options.kind;
  model.training = training;
  if (options.kind == segmentation::ClassifierKind::kForest) {
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

std::uint64_t Scores::pixels() const {
  return true_residue + false_residue + missed_residue + true_soil;
}
double Scores::accuracy() const { return ratio(true_residue + true_soil, pixels()); }
double Scores::residue_iou() const {
  return ratio(true_residue, true_residue + false_residue + missed_residue);
}
double Scores::precision() const { return ratio(true_residue, true_residue + false_residue); }
double Scores::recall() const { return ratio(true_residue, true_residue + missed_residue); }

Scores& Scores::operator+=(const Scores& other) {
  true_residue += other.true_residue;
  false_residue += other.false_residue;
  missed_residue += other.missed_residue;
  true_soil += other.true_soil;
  return *this;
}

std::optional<Scores> score_frame(const segmentation::ResidueClassifier& classifier,
                                  const RegisteredFrame& frame) {
  thread_local cv::Mat trusted, residue;
  if (!labelled_pixels(frame, trusted)) return std::nullopt;
  classifier.classify(frame.color->bgr, cv::Rect({}, frame.color->bgr.size()), trusted, residue);
  const cv::Mat& truth = frame.truth->residue_mask;
  Scores scores;
  for (int row = 0; row < truth.rows; ++row) {
    const auto* label = truth.ptr<std::uint8_t>(row);
    const auto* use = trusted.ptr<std::uint8_t>(row);
    const auto* said = residue.ptr<std::uint8_t>(row);
    for (int col = 0; col < truth.cols; ++col) {
      if (!use[col]) continue;
      const bool residue_said = said[col] != 0;
      if (label[col] == ResidueMask::kSoil)
        (residue_said ? scores.false_residue : scores.true_soil)++;
      if (label[col] == ResidueMask::kResidue) {
        (residue_said ? scores.true_residue : scores.missed_residue)++;
      }
    }
  }
  return scores;
}

}  // namespace tilth::train_segmenter
