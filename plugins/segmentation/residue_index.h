// Colour indices that tell residue from soil, each with its automatic threshold (Otsu's,
// on the frame's own histogram) and, for frames that show one material only, an absolute
// boundary. docs/segmentation-variants.md explains the indices and the constants.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "tilth/param_spec.h"

namespace tilth::segmentation {

enum class ColorIndex { kExg, kExr, kExgr, kHue };

ColorIndex parse_color_index(const std::string& name);  // throws naming the known ones
std::vector<std::string> color_index_names();

// How one frame's colours were split.
struct IndexSplit {
  float threshold = 0;        // the index value between soil and residue
  float class_gap = 0;        // between the means of Otsu's two classes (0: no split)
  float min_gap = 0;          // the index's least gap between two materials
  bool two_classes = false;   // false: the frame shows one material, `threshold` is absolute
  bool residue_above = true;  // residue's side of the threshold
  int smoothing_px = 0;       // the box the colours were averaged over: (2r+1)^2

  std::string text() const;  // "class gap 0.012, two materials from 0.05"
};

// The middle and the spread of a set of pixels' index: the median, and the robust
// standard deviation (1.4826 times the median absolute deviation).
struct IndexSpread {
  float median = 0;
  float sigma = 0;
};

class ResidueIndex {
 public:
  // `smoothing_px`: the index is that of the mean colour over a (2r+1)^2 box. Noisier
  // colours (a camera's gain in low light) are averaged over larger boxes, up to
  // `max_smoothing_px`, until the noise of the soil's index is under kNoiseShareOfGap of
  // the index's least gap between two materials.
  ResidueIndex(ColorIndex index, int smoothing_px, int max_smoothing_px);

  // The simulator's scenes through the paper rig's camera (2 DN of noise) keep the 3x3 box;
  // at 6 DN heavy cover lost half its visible soil to noise with a 3x3 box, and every
  // frame with it (docs/accuracy.md, "Noisier cameras").
  static constexpr float kNoiseShareOfGap = 0.6f;

  // Writes 255 into `residue` (CV_8UC1) where a pixel's index is on the residue side of
  // the frame's threshold, 0 elsewhere. The threshold is Otsu's over the pixels not marked
  // in `untrusted`, unless the means of its two classes lie closer than the index's
  // minimum gap: then the frame shows one material, and the absolute boundary decides.
  IndexSplit classify(const cv::Mat& bgr, const cv::Mat& untrusted, cv::Mat& residue) const;
  // The same, and each pixel's index (CV_32FC1, NaN without colour) in `index`.
  IndexSplit classify(const cv::Mat& bgr, const cv::Mat& untrusted, cv::Mat& residue,
                      cv::Mat& index) const;

  // The spread of `index` (as classify writes it) over the pixels marked in `among`
  // (CV_8UC1), to within a thousandth of the index's range, from every second pixel of
  // every second row; empty for fewer than kMinSpreadPixels of those with a colour.
  std::optional<IndexSpread> spread(const cv::Mat& index, const cv::Mat& among) const;
  static constexpr int kMinSpreadPixels = 100;

 private:
  IndexSplit split_at(int smoothing_px, const cv::Mat& bgr, const cv::Mat& untrusted,
                      cv::Mat& index) const;

  const ColorIndex index_;
  const int smoothing_px_;
  const int max_smoothing_px_;
};

// The `index` and `max_smoothing_px` parameters of the stages that use it.
ParamSpec color_index_param();
ParamSpec max_smoothing_px_param();

}  // namespace tilth::segmentation
