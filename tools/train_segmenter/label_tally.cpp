#include "label_tally.h"

#include <cstdio>

#include "tilth/messages/residue_mask.h"

namespace tilth::train_segmenter {
namespace {

double ratio(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

std::string formatted(const char* format, double value) {
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string percent(std::uint64_t part, std::uint64_t whole) {
  return formatted("%.2f %%", 100.0 * ratio(part, whole));
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

std::string tally_text(const LabelTally& tally) {
  std::string text = "depth labels " + percent(tally.labelled(), tally.pixels) +
                     " of its pixels with trusted colour (soil " +
                     percent(tally.soil, tally.pixels) + ", residue " +
                     percent(tally.residue, tally.pixels) + ")";
  if (tally.judged == 0) return text + "; it has no mask to compare them with";
  return text + "; they agree with its mask on " + percent(tally.agreeing, tally.judged) +
         " of the " + std::to_string(tally.judged) + " pixels both label";
}

std::string depth_labels_text(const segmentation::DepthLabelOptions& options) {
  return "soil within " + formatted("%g", options.soil_within_mm) + " mm, residue above " +
         formatted("%g", options.residue_above_mm) + " mm, edge " +
         std::to_string(options.edge_px) + " px, " +
         (options.envelope_px > 0 ? "envelope " + formatted("%g", options.envelope_px) + " px"
                                  : std::string("a plane"));
}

}  // namespace tilth::train_segmenter
