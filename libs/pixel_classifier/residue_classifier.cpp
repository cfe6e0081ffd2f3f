#include "pixel_classifier/residue_classifier.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

#include "pixel_classifier/pixel_features.h"

namespace tilth::segmentation {
namespace {

// Whether the trees score row (or column) `index` of `count`: every `step`-th and the last.
bool sampled(int index, int count, int step) { return index % step == 0 || index == count - 1; }

// The sampled rows (or columns) around `index`: itself when it is sampled, else the
// sampled ones just below and above it.
std::pair<int, int> bracket(int index, int count, int step) {
  if (sampled(index, count, step)) return {index, index};
  const int below = index - index % step;
  return {below, std::min(below + step, count - 1)};
}

}  // namespace

ResidueClassifier::ResidueClassifier(const ClassifierModel& model, int scored_every_px)
    : features_(model.features), ensemble_(*model.trees, model.kind), step_(scored_every_px) {}

void ResidueClassifier::classify(const cv::Mat& bgr, const cv::Rect& area, const cv::Mat& counted,
                                 cv::Mat& residue) const {
  thread_local PixelFeatures features;
  thread_local std::vector<int> columns;
  thread_local std::vector<float> values, scores;
  features.compute(features_, bgr, area, counted);
  const std::size_t count = feature_names(features_).size();
  // The trees' decisions on `columns` of a row, all at once.
  const auto decide = [&](int row, std::uint8_t* out) {
    values.resize(columns.size() * count);
    scores.resize(columns.size());
    for (std::size_t i = 0; i < columns.size(); ++i) {
      features.at(row, columns[i], values.data() + i * count);
    }
    ensemble_.score(values.data(), count, columns.size(), scores.data());
    for (std::size_t i = 0; i < columns.size(); ++i) out[columns[i]] = scores[i] > 0 ? 255 : 0;
  };
  residue.create(area.size(), CV_8UC1);
  const int rows = area.height, cols = area.width;
  for (int row = 0; row < rows; ++row) {
    if (!sampled(row, rows, step_)) continue;
    columns.clear();
    for (int col = 0; col < cols; ++col) {
      if (sampled(col, cols, step_)) columns.push_back(col);
    }
    decide(row, residue.ptr<std::uint8_t>(row));
  }
  for (int row = 0; row < rows; ++row) {
    const auto [above, below] = bracket(row, rows, step_);
    const auto* top = residue.ptr<std::uint8_t>(above);
    const auto* bottom = residue.ptr<std::uint8_t>(below);
    auto* out = residue.ptr<std::uint8_t>(row);
    const bool row_sampled = sampled(row, rows, step_);
    columns.clear();
    for (int col = 0; col < cols; ++col) {
      if (row_sampled && sampled(col, cols, step_)) continue;
      const auto [left, right] = bracket(col, cols, step_);
      const std::uint8_t corner = top[left];
      if (top[right] == corner && bottom[left] == corner && bottom[right] == corner) {
        out[col] = corner;
      } else {
        columns.push_back(col);
      }
    }
    decide(row, out);
  }
}

}  // namespace tilth::segmentation
