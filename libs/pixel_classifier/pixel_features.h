// What the trained pixel classifier sees of a pixel, shared by segmentation.
// pixel_classifier and tilth train-segmenter so that both see the same thing: the pixel's
// colour averaged over a 3x3 box and quantised to 6 bits per channel (its colour cell),
// described by the features of the cell's centre colour.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace tilth::segmentation {

inline constexpr int kCellBits = 6;
inline constexpr int kCellCount = 1 << (3 * kCellBits);  // 262 144
inline constexpr int kFeatureSmoothingPx = 1;

// "L*", "a*", "b*", "H", "S", "V", "exg", "a*/L*", "b*/L*": the order of the feature columns.
const std::vector<std::string>& pixel_feature_names();

// The colour cell of each pixel of a CV_8UC3 BGR image (CV_32SC1).
void color_cells(const cv::Mat& bgr, cv::Mat& cells);

// One row of features (CV_32F) per colour cell, in cell order; computed once.
const cv::Mat& cell_features();

}  // namespace tilth::segmentation
