// A model's decision for every pixel of a frame: its feature set's features, scored by
// its trees. segmentation.pixel_classifier and tilth train-segmenter's scores both use it.
#pragma once

#include <opencv2/core/mat.hpp>

#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/tree_ensemble.h"

namespace tilth::segmentation {

// The default of scored_every_px: with it the held-out residue IoU on the simulated
// recordings is the same or up to 0.004 higher than scoring every pixel
// (docs/segmentation-variants.md).
inline constexpr int kScoredEveryPx = 2;
inline constexpr int kMaxScoredEveryPx = 4;

class ResidueClassifier {
 public:
  // The trees score every `scored_every_px`-th pixel of every `scored_every_px`-th row (and
  // the last row and column); a pixel between them takes their decision where they agree
  // and is scored itself where they do not (at the boundaries). 1: every pixel is scored.
  ResidueClassifier(const ClassifierModel& model, int scored_every_px);

  // 255 (residue) or 0 (soil) for every pixel of `area` of a CV_8UC3 BGR image (CV_8UC1 of
  // the area's size), from the features PixelFeatures computes; `counted` as for it.
  void classify(const cv::Mat& bgr, const cv::Rect& area, const cv::Mat& counted,
                cv::Mat& residue) const;

 private:
  const FeatureSet features_;
  const TreeEnsemble ensemble_;
  const int step_;
};

}  // namespace tilth::segmentation
