#include "label_tally.h"

#include "tilth/messages/residue_mask.h"

namespace tilth::train_segmenter {
namespace {

double ratio(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

}  // namespace

double LabelTally::coverage() const { return ratio(labelled(), pixels); }
double LabelTally::agreement() const { return ratio(agreeing, judged); }

LabelTally& LabelTally::operator+=(const LabelTally& other) {
  pixels += other.pixels;
  soil += other.soil;
  residue += other.residue;
  judged += other.judged;
  agreeing += other.agreeing;
  return *this;
}

LabelTally tally_labels(const cv::Mat& labels, const RegisteredFrame& frame) {
  const cv::Mat& truth = frame.truth->residue_mask;
  const bool masked = !truth.empty() && truth.size() == labels.size();
  const cv::Mat trusted = frame.color->status == RegisteredColor::kValid;
  LabelTally tally;
  for (int row = 0; row < labels.rows; ++row) {
    const auto* label = labels.ptr<std::uint8_t>(row);
    const auto* use = trusted.ptr<std::uint8_t>(row);
    const auto* is = masked ? truth.ptr<std::uint8_t>(row) : nullptr;
    for (int col = 0; col < labels.cols; ++col) {
      if (!use[col]) continue;
      ++tally.pixels;
      if (label[col] != ResidueMask::kSoil && label[col] != ResidueMask::kResidue) continue;
      ++(label[col] == ResidueMask::kSoil ? tally.soil : tally.residue);
      if (is && (is[col] == ResidueMask::kSoil || is[col] == ResidueMask::kResidue)) {
        ++tally.judged;
        tally.agreeing += is[col] == label[col];
      }
    }
  }
  return tally;
}

}  // namespace tilth::train_segmenter
