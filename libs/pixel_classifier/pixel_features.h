// What the trained pixel classifier sees of each pixel, shared by segmentation.
// pixel_classifier and tilth train-segmenter so that both see the same thing: the colour
// averaged over a 3x3 box, described by the features of a FeatureSet.
#pragma once

#include <opencv2/core/mat.hpp>

#include "pixel_classifier/feature_set.h"
#include "pixel_classifier/set_features.h"

namespace tilth::segmentation {

inline constexpr int kFeatureSmoothingPx = 1;

// How far around a pixel its features look, px: the smoothing, and for the texture set
// the Sobel kernel and the half-width of the largest window.
int feature_reach_px(FeatureSet set);

// The features of the pixels of an area of an image, computed once per image and read
// pixel by pixel, so that a caller that scores only some pixels assembles only theirs.
// The planes are reused from image to image: nothing is allocated in the steady state.
class PixelFeatures {
 public:
  // `area` of a CV_8UC3 BGR image; its features are computed from the image's pixels up to
  // feature_reach_px around it, so that they equal those of the whole image (borders
  // reflected at the image's edges). `counted` (CV_8UC1 of the area's size, non-zero
  // counted; empty: every pixel) are the pixels whose median luminance normalises the
  // texture set.
  void compute(FeatureSet set, const cv::Mat& bgr, const cv::Rect& area, const cv::Mat& counted);

  // feature_names(set).size() values: those of pixel (row, col) of the area.
  void at(int row, int col, float* out) const;

 private:
  FeatureSet set_ = FeatureSet::kTexture;
  cv::Mat smoothed_;
  ColourPlanes colour_;
  TexturePlanes texture_;
};

// The features of every pixel of a CV_8UC3 BGR image: one CV_32F row per pixel (row-major
// order), one column per feature_names(set); `counted` as for PixelFeatures::compute.
void pixel_features(FeatureSet set, const cv::Mat& bgr, const cv::Mat& counted, cv::Mat& features);

// The colour the features describe: a CV_8UC3 BGR image averaged over a
// (2*kFeatureSmoothingPx+1)^2 box, borders reflected (at the edges of the image a view
// belongs to).
void smoothed_colour(const cv::Mat& bgr, cv::Mat& smoothed);

// The luminance 0.114 B + 0.587 G + 0.299 R (DN, CV_32F) of a smoothed colour image, and the
// median of it rounded to whole DN over the `counted` pixels (the lower median; every pixel
// when none is counted; at least 1 DN).
void luminance(const cv::Mat& smoothed, cv::Mat& luminance_dn);
float median_luminance(const cv::Mat& luminance_dn, const cv::Mat& counted);

}  // namespace tilth::segmentation
