#include "image_folder/pixel_checks.h"

namespace tilth::recording {

std::string describe_pixels(int type, cv::Size size) {
  return std::to_string(CV_ELEM_SIZE1(type) * 8) + "-bit " + std::to_string(CV_MAT_CN(type)) +
         "-channel, " + std::to_string(size.width) + "x" + std::to_string(size.height) + " pixels";
}

std::string pixel_mismatch(const cv::Mat& image, int type, cv::Size size,
                           std::string_view size_origin) {
  if (image.type() == type && image.size() == size) return "";
  return "expected " + describe_pixels(type, size) + " (" + std::string(size_origin) + "), got " +
         describe_pixels(image.type(), image.size());
}

}  // namespace tilth::recording
