// Whether an image holds what the recording format expects (bit depth, channels, size),
// said the same way by the source and the writer.
#pragma once

#include <string>
#include <string_view>

#include <opencv2/core/mat.hpp>

namespace tilth::recording {

// "16-bit 1-channel, 640x480 pixels"
std::string describe_pixels(int type, cv::Size size);

// Empty when `image` is of `type` and `size`; otherwise "expected <type and size>
// (<size_origin>), got <what it is>".
std::string pixel_mismatch(const cv::Mat& image, int type, cv::Size size,
                           std::string_view size_origin);

}  // namespace tilth::recording
