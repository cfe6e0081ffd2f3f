#include "segmenter_training.h"

#include <algorithm>
#include <random>

#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/pixel_features.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::train_segmenter {
namespace {

using segmentation::kResidueClass;
using segmentation::kSoilClass;

// Calls `visit(cell, label)` for every pixel that takes part.
template <class Visit>
bool for_each_labelled_pixel(const RegisteredFrame& frame, Visit visit) {
  const cv::Mat& truth = frame.truth->residue_mask;
  if (truth.empty()) return false;
  if (truth.size() != frame.color->bgr.size() || truth.type() != CV_8UC1) {
    throw Error("frame " + std::to_string(frame.frame_id) + ": the ground-truth mask is " +
                std::to_string(truth.cols) + "x" + std::to_string(truth.rows) +
                " (expected 8-bit, the depth image's " + std::to_string(frame.color->bgr.cols) +
                "x" + std::to_string(frame.color->bgr.rows) + ")");
  }
  thread_local cv::Mat cells;
  segmentation::color_cells(frame.color->bgr, cells);
  for (int row = 0; row < truth.rows; ++row) {
    const auto* label = truth.ptr<std::uint8_t>(row);
    const auto* status = frame.color->status.ptr<std::uint8_t>(row);
    const auto* cell = cells.ptr<std::int32_t>(row);
    for (int col = 0; col < truth.cols; ++col) {
      if (status[col] != RegisteredColor::kValid) continue;
      if (label[col] == ResidueMask::kSoil) visit(cell[col], kSoilClass);
      if (label[col] == ResidueMask::kResidue) visit(cell[col], kResidueClass);
    }
  }
  return true;
}

}  // namespace

bool TrainingSet::sample(const RegisteredFrame& frame, std::size_t per_class, std::uint64_t seed) {
  std::array<std::vector<std::int32_t>, 2> by_class;
  const bool labelled = for_each_labelled_pixel(
      frame, [&](std::int32_t cell, int label) { by_class[label].push_back(cell); });
  if (!labelled) return false;
  std::mt19937_64 rng(seed);
  for (int label : {kSoilClass, kResidueClass}) {
    std::vector<std::int32_t> drawn;
    std::sample(by_class[label].begin(), by_class[label].end(), std::back_inserter(drawn),
                per_class, rng);
    cells_.insert(cells_.end(), drawn.begin(), drawn.end());
    labels_.insert(labels_.end(), drawn.size(), label);
    counts_[label] += drawn.size();
  }
  return true;
}

cv::Ptr<cv::ml::RTrees> TrainingSet::train(int trees, int depth) const {
  if (soil() == 0 || residue() == 0) {
    throw Error("the training frames show " + std::to_string(soil()) + " soil and " +
                std::to_string(residue()) +
                " residue pixels (expected both classes in the ground-truth masks)");
  }
  const cv::Mat& table = segmentation::cell_features();
  cv::Mat features(static_cast<int>(cells_.size()), table.cols, CV_32F);
  for (std::size_t i = 0; i < cells_.size(); ++i)
    table.row(cells_[i]).copyTo(features.row(static_cast<int>(i)));
  const cv::Mat responses(labels_, true);

  cv::Ptr<cv::ml::RTrees> forest = cv::ml::RTrees::create();
  forest->setMaxDepth(depth);
  forest->setMinSampleCount(5);
  forest->setTermCriteria({cv::TermCriteria::MAX_ITER, trees, 0});
  forest->train(cv::ml::TrainData::create(features, cv::ml::ROW_SAMPLE, responses));
  return forest;
}

HeldOutPixels::HeldOutPixels() : counts_(segmentation::kCellCount) {}

bool HeldOutPixels::add(const RegisteredFrame& frame) {
  return for_each_labelled_pixel(frame, [&](std::int32_t cell, int label) {
    ++counts_[cell][label];
    ++pixels_;
  });
}

Scores HeldOutPixels::score(const std::vector<std::uint8_t>& residue_by_cell) const {
  std::uint64_t true_residue = 0, false_residue = 0, missed_residue = 0, true_soil = 0;
  for (std::size_t cell = 0; cell < counts_.size(); ++cell) {
    const bool residue = residue_by_cell[cell] != 0;
    (residue ? false_residue : true_soil) += counts_[cell][kSoilClass];
    (residue ? true_residue : missed_residue) += counts_[cell][kResidueClass];
  }
  auto ratio = [](std::uint64_t part, std::uint64_t whole) {
    return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
  };
  Scores scores;
  scores.pixels = pixels_;
  scores.accuracy = ratio(true_residue + true_soil, pixels_);
  scores.residue_iou = ratio(true_residue, true_residue + false_residue + missed_residue);
  scores.precision = ratio(true_residue, true_residue + false_residue);
  scores.recall = ratio(true_residue, true_residue + missed_residue);
  return scores;
}

}  // namespace tilth::train_segmenter
