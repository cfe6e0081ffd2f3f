// libs/color: every pixel format to BGR and to grey. A Bayer mosaic of a uniform colour
// must come back as that colour, which only the right OpenCV code for each GenICam
// pattern gives (a wrong one swaps red and blue, or reads green as red).
#include "color/color_conversion.h"

#include <array>
#include <string>

#include <gtest/gtest.h>

#include "tilth/error.h"

namespace tilth::color {
namespace {

constexpr int kBlue = 30, kGreen = 120, kRed = 210;

// A uniform colour laid out as the mosaic `pattern`: the colours of its 2x2 tile, top
// left first, as GenICam names it ("RGGB": R G / G B).
cv::Mat mosaic(const std::string& pattern) {
  const auto value = [](char channel) {
    return channel == 'R' ? kRed : channel == 'G' ? kGreen : kBlue;
  };
  cv::Mat out(8, 10, CV_8UC1);
  for (int y = 0; y < out.rows; ++y) {
    for (int x = 0; x < out.cols; ++x) {
      out.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(value(pattern[(y % 2) * 2 + x % 2]));
    }
  }
  return out;
}

void expect_uniform_bgr(const cv::Mat& bgr, const std::string& what) {
  ASSERT_EQ(bgr.type(), CV_8UC3) << what;
  for (int y = 2; y < bgr.rows - 2; ++y) {
    for (int x = 2; x < bgr.cols - 2; ++x) {
      EXPECT_EQ(bgr.at<cv::Vec3b>(y, x), cv::Vec3b(kBlue, kGreen, kRed))
          << what << " at (" << x << ", " << y << ")";
    }
  }
}

TEST(ColorConversion, EachBayerPatternDemosaicsToItsOwnColours) {
  const std::array<std::pair<PixelFormat, std::string>, 4> patterns = {{
      {PixelFormat::kBayerRggb8, "RGGB"},
      {PixelFormat::kBayerBggr8, "BGGR"},
      {PixelFormat::kBayerGrbg8, "GRBG"},
      {PixelFormat::kBayerGbrg8, "GBRG"},
  }};
  for (const auto& [format, pattern] : patterns) {
    cv::Mat bgr;
    to_bgr(mosaic(pattern), format, bgr);
    expect_uniform_bgr(bgr, pattern);

    cv::Mat gray;
    to_gray(mosaic(pattern), format, gray);
    ASSERT_EQ(gray.type(), CV_8UC1);
    // BT.601: 0.299 R + 0.587 G + 0.114 B = 136.65; OpenCV rounds its fixed-point sum.
    EXPECT_NEAR(gray.at<std::uint8_t>(4, 5), 136.65, 1.0) << pattern;
  }
}

TEST(ColorConversion, PackedAndGreyImagesConvertAsTheirFormatSays) {
  const cv::Mat rgb(4, 6, CV_8UC3, cv::Scalar(kRed, kGreen, kBlue));
  cv::Mat bgr;
  to_bgr(rgb, PixelFormat::kRgb8, bgr);
  expect_uniform_bgr(bgr, "rgb8");

  const cv::Mat original(4, 6, CV_8UC3, cv::Scalar(kBlue, kGreen, kRed));
  to_bgr(original, PixelFormat::kBgr8, bgr);
  expect_uniform_bgr(bgr, "bgr8");
  EXPECT_NE(bgr.data, original.data);  // a copy, not a view

  const cv::Mat grey(4, 6, CV_8UC1, cv::Scalar(77));
  to_bgr(grey, PixelFormat::kMono8, bgr);
  EXPECT_EQ(bgr.at<cv::Vec3b>(1, 1), cv::Vec3b(77, 77, 77));
  cv::Mat gray;
  to_gray(grey, PixelFormat::kMono8, gray);
  EXPECT_EQ(gray.at<std::uint8_t>(1, 1), 77);
}

TEST(ColorConversion, PixelsThatDoNotMatchTheirFormatAreRefused) {
  cv::Mat out;
  try {
    to_bgr(cv::Mat(4, 6, CV_16UC1), PixelFormat::kBayerRggb8, out);
    ADD_FAILURE() << "16-bit pixels taken for an 8-bit mosaic";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "a bayer_rggb8 image has 1 channel(s) of 8 bits; this one has 1 of 16 bits");
  }
  EXPECT_THROW(to_gray(cv::Mat(4, 6, CV_8UC1), PixelFormat::kBgr8, out), Error);
}

}  // namespace
}  // namespace tilth::color
