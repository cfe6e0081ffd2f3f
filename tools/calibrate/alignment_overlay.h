// The picture of a check: the registered colour with the depth edges and the colour
// edges drawn over it, so a person sees whether (and which way) they are apart.
#pragma once

#include <string>

#include <opencv2/core/mat.hpp>

namespace tilth::calibrate {

// Each depth pixel drawn as a block of this many screen pixels, so one-pixel edges stay
// visible and a one-pixel offset can be told.
constexpr int kOverlayScale = 2;

// `bgr` (CV_8UC3) dimmed, depth edges magenta, colour edges green, both white;
// `caption` printed in the top-left corner.
cv::Mat alignment_overlay(const cv::Mat& bgr, const cv::Mat& depth_edges,
                          const cv::Mat& color_edges, const std::string& caption);

}  // namespace tilth::calibrate
