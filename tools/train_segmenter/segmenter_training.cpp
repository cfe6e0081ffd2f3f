#include "segmenter_training.h"

#include <string>

#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::train_segmenter {
namespace {

// Which pixels of the frame may take part (trusted colour), once `labels` (`what`: the
// ground-truth mask, ...) is checked to fit the frame.
void trusted_pixels(const RegisteredFrame& frame, const cv::Mat& labels, const char* what,
                    cv::Mat& trusted) {
  if (labels.size() != frame.color->bgr.size() || labels.type() != CV_8UC1) {
    throw Error("frame " + std::to_string(frame.frame_id) + ": " + what + " is " +
                std::to_string(labels.cols) + "x" + std::to_string(labels.rows) +
                " (expected 8-bit, the depth image's " + std::to_string(frame.color->bgr.cols) +
                "x" + std::to_string(frame.color->bgr.rows) + ")");
  }
  trusted = frame.color->status == RegisteredColor::kValid;
}

// The library's samples of `labels` (`what`: named in errors) among the frame's pixels.
void draw(segmentation::TrainingSet& set, const RegisteredFrame& frame, const cv::Mat& labels,
          const char* what, std::size_t per_class, std::uint64_t seed) {
  thread_local cv::Mat trusted;
  trusted_pixels(frame, labels, what, trusted);
  set.sample(frame.color->bgr, trusted, labels, per_class, seed,
             "frame " + std::to_string(frame.frame_id) + ": " + what);
}

double ratio(std::uint64_t part, std::uint64_t whole) {
  return whole == 0 ? 0.0 : static_cast<double>(part) / static_cast<double>(whole);
}

}  // namespace

bool TrainingSet::sample(const RegisteredFrame& frame, std::size_t per_class, std::uint64_t seed) {
  if (frame.truth->residue_mask.empty()) return false;
  draw(*this, frame, frame.truth->residue_mask, "the ground-truth mask", per_class, seed);
  return true;
}

void TrainingSet::sample(const RegisteredFrame& frame, const cv::Mat& labels, std::size_t per_class,
                         std::uint64_t seed) {
  draw(*this, frame, labels, "the labels", per_class, seed);
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

Scores score_mask(const cv::Mat& residue, const cv::Mat& truth, const cv::Mat& trusted) {
  Scores scores;
  for (int row = 0; row < truth.rows; ++row) {
    const auto* label = truth.ptr<std::uint8_t>(row);
    const auto* use = trusted.ptr<std::uint8_t>(row);
    const auto* said = residue.ptr<std::uint8_t>(row);
    for (int col = 0; col < truth.cols; ++col) {
      if (!use[col]) continue;
      const bool residue_said = said[col] != 0;
      if (label[col] == ResidueMask::kSoil) {
        (residue_said ? scores.false_residue : scores.true_soil)++;
      }
      if (label[col] == ResidueMask::kResidue) {
        (residue_said ? scores.true_residue : scores.missed_residue)++;
      }
    }
  }
  return scores;
}

std::optional<Scores> score_frame(const segmentation::ResidueClassifier& classifier,
                                  const RegisteredFrame& frame) {
  thread_local cv::Mat trusted, residue;
  if (frame.truth->residue_mask.empty()) return std::nullopt;
  trusted_pixels(frame, frame.truth->residue_mask, "the ground-truth mask", trusted);
  classifier.classify(frame.color->bgr, cv::Rect({}, frame.color->bgr.size()), trusted, residue);
  return score_mask(residue, frame.truth->residue_mask, trusted);
}

}  // namespace tilth::train_segmenter
