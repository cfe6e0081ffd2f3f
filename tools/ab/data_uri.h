// Images embedded in the report as data: URIs, so the page needs no other file. JPEG:
// a photo-like overlay is ~8x smaller than as PNG.
#pragma once

#include <string>
#include <string_view>

#include <opencv2/core/mat.hpp>

namespace tilth::ab {

std::string base64(std::string_view bytes);
// Throws tilth::Error when OpenCV cannot encode the image.
std::string jpeg_data_uri(const cv::Mat& image, int quality);

}  // namespace tilth::ab
