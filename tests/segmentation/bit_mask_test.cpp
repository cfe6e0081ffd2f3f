// BitMask's square dilation and erosion against cv::dilate and cv::erode (default border)
// on random binary images: widths below, at and across word boundaries, radii from one
// pixel to wider than the image, sparse and dense masks.
#include "bit_mask.h"

#include <string>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace tilth::segmentation {
namespace {

BitMask packed(const cv::Mat& binary) {
  BitMask mask;
  mask.resize(binary.rows, binary.cols);
  for (int y = 0; y < binary.rows; ++y) {
    std::uint64_t* words = mask.row(y);
    std::fill_n(words, mask.words_per_row(), 0);
    for (int x = 0; x < binary.cols; ++x) {
      if (binary.at<std::uint8_t>(y, x) != 0) words[x / 64] |= std::uint64_t{1} << (x % 64);
    }
  }
  return mask;
}

// Pixels where `mask` differs from `expected` (255/0); padding bits must stay 0.
int mismatches(const BitMask& mask, const cv::Mat& expected) {
  int wrong = 0;
  for (int y = 0; y < expected.rows; ++y) {
    for (int x = 0; x < mask.words_per_row() * 64; ++x) {
      const bool want = x < expected.cols && expected.at<std::uint8_t>(y, x) != 0;
      wrong += mask.at(y, x) != want ? 1 : 0;
    }
  }
  return wrong;
}

struct Shape {
  int rows;
  int cols;
};

class RandomMasks : public ::testing::TestWithParam<Shape> {};

TEST_P(RandomMasks, DilateAndErodeEqualOpenCVs) {
  const Shape shape = GetParam();
  cv::RNG random(static_cast<std::uint64_t>(shape.rows * 1000 + shape.cols));
  BitMask scratch;
  int compared = 0;
  for (const int percent_set : {3, 50, 97}) {
    cv::Mat noise(shape.rows, shape.cols, CV_8UC1);
    random.fill(noise, cv::RNG::UNIFORM, 0, 100);
    const cv::Mat binary = noise < percent_set;
    for (const int radius : {0, 1, 2, 3, 5, 33, 70}) {
      const cv::Mat square =
          cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1});
      const std::string where = std::to_string(shape.cols) + "x" + std::to_string(shape.rows) +
                                ", " + std::to_string(percent_set) + " % set, radius " +
                                std::to_string(radius);
      cv::Mat dilated;
      cv::Mat eroded;
      cv::dilate(binary, dilated, square);
      cv::erode(binary, eroded, square);
      BitMask dilation = packed(binary);
      BitMask erosion = packed(binary);
      dilation.dilate(radius, scratch);
      erosion.erode(radius, scratch);
      EXPECT_EQ(mismatches(dilation, dilated), 0) << "dilate, " << where;
      EXPECT_EQ(mismatches(erosion, eroded), 0) << "erode, " << where;
      ++compared;
    }
  }
  EXPECT_EQ(compared, 21);
}

INSTANTIATE_TEST_SUITE_P(BitMask, RandomMasks,
                         ::testing::Values(Shape{1, 1}, Shape{3, 7}, Shape{10, 64}, Shape{33, 65},
                                           Shape{70, 130}, Shape{48, 200}, Shape{480, 640}),
                         [](const auto& info) {
                           return std::to_string(info.param.cols) + "x" +
                                  std::to_string(info.param.rows);
                         });

// An opening (erosion, then dilation) followed by a dilation is one erosion and one larger
// dilation: what segmentation.color_threshold relies on to despeckle and dilate at once.
TEST(BitMask, OpeningThenDilationIsErosionThenTheSummedDilation) {
  cv::RNG random(7);
  cv::Mat noise(96, 150, CV_8UC1);
  random.fill(noise, cv::RNG::UNIFORM, 0, 100);
  const cv::Mat binary = noise < 40;
  const auto square = [](int radius) {
    return cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1});
  };
  for (const int speckle : {1, 2}) {
    for (const int dilation : {1, 2, 4}) {
      cv::Mat expected;
      cv::morphologyEx(binary, expected, cv::MORPH_OPEN, square(speckle));
      cv::dilate(expected, expected, square(dilation));
      BitMask mask = packed(binary);
      BitMask scratch;
      mask.erode(speckle, scratch);
      mask.dilate(speckle + dilation, scratch);
      EXPECT_EQ(mismatches(mask, expected), 0) << speckle << ", " << dilation;
    }
  }
}

}  // namespace
}  // namespace tilth::segmentation
