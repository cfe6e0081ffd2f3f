// Each pixel's colour summed over the box around it, the colour indices' smoothing: the
// result of cv::boxFilter unnormalised into 16 bits, in a quarter of its time on the
// segmented area (two passes of plain loops that the compiler vectorises).
#pragma once

#include <opencv2/core/mat.hpp>

namespace tilth::segmentation {

// `summed` (CV_16UC3, the size of `bgr`, a CV_8UC3 image or a view into one): each
// channel summed over the (2r+1)^2 box around the pixel, r = `radius` (0..3, so that a
// sum fits in 16 bits). A view sums the pixels its image has around it; at the image's
// edges the box is reflected with the edge pixel repeated (BORDER_REFLECT).
void box_sums(const cv::Mat& bgr, int radius, cv::Mat& summed);

}  // namespace tilth::segmentation
