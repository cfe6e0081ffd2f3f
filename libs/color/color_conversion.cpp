#include "color/color_conversion.h"

#include <opencv2/imgproc.hpp>

#include "tilth/error.h"

namespace tilth::color {
namespace {

struct Codes {
  int to_bgr;
  int to_gray;
};

// -1: a plain copy.
Codes codes(PixelFormat format) {
  switch (format) {
    case PixelFormat::kBgr8:
      return {-1, cv::COLOR_BGR2GRAY};
    case PixelFormat::kRgb8:
      return {cv::COLOR_RGB2BGR, cv::COLOR_RGB2GRAY};
    case PixelFormat::kMono8:
      return {cv::COLOR_GRAY2BGR, -1};
    case PixelFormat::kBayerRggb8:
      return {cv::COLOR_BayerBG2BGR, cv::COLOR_BayerBG2GRAY};
    case PixelFormat::kBayerBggr8:
      return {cv::COLOR_BayerRG2BGR, cv::COLOR_BayerRG2GRAY};
    case PixelFormat::kBayerGrbg8:
      return {cv::COLOR_BayerGB2BGR, cv::COLOR_BayerGB2GRAY};
    case PixelFormat::kBayerGbrg8:
      return {cv::COLOR_BayerGR2BGR, cv::COLOR_BayerGR2GRAY};
  }
  throw Error("colour image in an unknown pixel format");
}

void convert(const cv::Mat& pixels, PixelFormat format, int code, cv::Mat& out) {
  if (pixels.depth() != CV_8U || pixels.channels() != channels(format)) {
    throw Error("a " + std::string(to_string(format)) + " image has " +
                std::to_string(channels(format)) + " channel(s) of 8 bits; this one has " +
                std::to_string(pixels.channels()) + " of " +
                std::to_string(8 * CV_ELEM_SIZE1(pixels.type())) + " bits");
  }
  if (code < 0) {
    pixels.copyTo(out);
  } else {
    cv::cvtColor(pixels, out, code);
  }
}

}  // namespace

void to_bgr(const cv::Mat& pixels, PixelFormat format, cv::Mat& bgr) {
  convert(pixels, format, codes(format).to_bgr, bgr);
}

void to_gray(const cv::Mat& pixels, PixelFormat format, cv::Mat& gray) {
  convert(pixels, format, codes(format).to_gray, gray);
}

}  // namespace tilth::color
