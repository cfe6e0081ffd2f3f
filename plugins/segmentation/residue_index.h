// Colour indices that tell residue from soil, each with its automatic threshold (Otsu's,
// on the frame's own histogram) and, for frames that show one material only, an absolute
// boundary. docs/segmentation-variants.md explains the indices and the constants.
#pragma once

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
  float threshold = 0;       // the index value between soil and residue
  float class_gap = 0;       // between the means of Otsu's two classes (0: no split)
  float min_gap = 0;         // the index's least gap between two materials
  bool two_classes = false;  // false: the frame shows one material, `threshold` is absolute

  std::string text() const;  // "class gap 0.012, two materials from 0.05"
};

class ResidueIndex {
 public:
  // `smoothing_px`: the index is that of the mean colour over a (2r+1)^2 box.
  ResidueIndex(ColorIndex index, int smoothing_px);

  // Writes 255 into `residue` (CV_8UC1) where a pixel's index is on the residue side of
  // the frame's threshold, 0 elsewhere. The threshold is Otsu's over the pixels not marked
  // in `untrusted`, unless the means of its two classes lie closer than the index's
  // minimum gap: then the frame shows one material, and the absolute boundary decides.
  IndexSplit classify(const cv::Mat& bgr, const cv::Mat& untrusted, cv::Mat& residue) const;

 private:
  const ColorIndex index_;
  const int smoothing_px_;
};

// The `index` parameter of the stages that use it.
ParamSpec color_index_param();

}  // namespace tilth::segmentation
