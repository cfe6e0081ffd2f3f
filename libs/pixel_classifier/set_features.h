// The features of each FeatureSet from the smoothed colour (pixel_features.h), one file
// per set; internal to the library. Each set's planes are images of the area whose
// features they hold; at() assembles one pixel's features from them.
#pragma once

#include <array>

#include <opencv2/core/mat.hpp>

#include "pixel_classifier/feature_set.h"

namespace tilth::segmentation {

class ColourPlanes {
 public:
  // `smoothed`: the area's smoothed colour.
  void compute(const cv::Mat& smoothed);
  void at(int row, int col, float* out) const;

 private:
  cv::Mat unit_, lab_, hsv_;
};

class TexturePlanes {
 public:
  // `smoothed`: the smoothed colour of the area's surroundings (feature_reach_px around it,
  // within the image), `area` within it; `counted` as for PixelFeatures::compute.
  void compute(const cv::Mat& smoothed, const cv::Rect& area, const cv::Mat& counted);
  void at(int row, int col, float* out) const;

 private:
  // The window sums are of c, c^2, gx^2, gy^2, gx*gy, where c is the luminance over its
  // median, less 1.
  enum Plane { kMean, kSquare, kXX, kYY, kXY, kPlanes };

  // The mean of `plane` over the window of `half` px around pixel (row, col) of the area.
  float window_mean(int plane, int half, int row, int col) const;

  cv::Mat luma_, centred_, gx_, gy_, padded_;
  std::array<cv::Mat, kPlanes> products_;  // c, c^2, gx^2, gy^2, gx*gy of the surroundings
  // Integral images (CV_64F) of the products over the area and the widest window's
  // half-width around it.
  std::array<cv::Mat, kPlanes> sums_;
  cv::Mat colour_, c_, dx_, dy_;  // views of the area
};

}  // namespace tilth::segmentation
