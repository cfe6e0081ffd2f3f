// Training segmentation.pixel_classifier's forest from frames with ground-truth masks:
// pixels sampled per frame and class, the forest, and its scores on held-out frames.
// Only pixels whose colour is trusted and whose truth is soil or residue (not mixed)
// take part.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/ml.hpp>

#include "registered_frames.h"

namespace tilth::train_segmenter {

class TrainingSet {
 public:
  // Adds up to `per_class` pixels of each class of the frame, drawn with `seed` (the same
  // seed, the same pixels). Returns false when the frame has no ground-truth mask.
  bool sample(const RegisteredFrame& frame, std::size_t per_class, std::uint64_t seed);

  std::size_t soil() const { return counts_[0]; }
  std::size_t residue() const { return counts_[1]; }

  // Random forest of `trees` trees no deeper than `depth`, on the samples' features.
  // Throws tilth::Error when a class has no samples.
  cv::Ptr<cv::ml::RTrees> train(int trees, int depth) const;

 private:
  std::vector<std::int32_t> cells_;
  std::vector<std::int32_t> labels_;
  std::array<std::size_t, 2> counts_{};
};

struct Scores {
  std::uint64_t pixels = 0;
  double accuracy = 0;     // share of pixels classified as the truth says
  double residue_iou = 0;  // |predicted and true residue| / |predicted or true residue|
  double precision = 0;    // of the pixels called residue, the share that is residue
  double recall = 0;       // of the residue pixels, the share called residue
};

// Counts, per colour cell, the held-out pixels of each class, so that any classifier of
// colour cells can be scored on them at once.
class HeldOutPixels {
 public:
  HeldOutPixels();
  // Returns false when the frame has no ground-truth mask.
  bool add(const RegisteredFrame& frame);
  // `residue_by_cell`: 255 residue, 0 soil, per colour cell.
  Scores score(const std::vector<std::uint8_t>& residue_by_cell) const;
  std::uint64_t pixels() const { return pixels_; }

 private:
  std::vector<std::array<std::uint32_t, 2>> counts_;  // per cell: soil, residue
  std::uint64_t pixels_ = 0;
};

}  // namespace tilth::train_segmenter
