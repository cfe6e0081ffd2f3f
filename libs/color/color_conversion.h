// A colour image's pixels as BGR or as grey, whatever pixel format it was stored in: the
// project's one table of OpenCV's conversion codes. OpenCV names a Bayer mosaic by its
// second row's second and third pixels, one pixel off the GenICam naming by the top-left
// tile (GenICam BayerRG8 is OpenCV's BayerBG).
#pragma once

#include <opencv2/core/mat.hpp>

#include "tilth/messages/color_image.h"

namespace tilth::color {

// 3-channel BGR: a mosaic demosaiced (bilinear), RGB reordered, grey replicated, BGR
// copied. `bgr` is reused when it has the size and type already.
void to_bgr(const cv::Mat& pixels, PixelFormat format, cv::Mat& bgr);

// 1-channel grey: a mosaic demosaiced straight to grey, colour weighted (ITU-R BT.601),
// grey copied.
void to_gray(const cv::Mat& pixels, PixelFormat format, cv::Mat& gray);

}  // namespace tilth::color
