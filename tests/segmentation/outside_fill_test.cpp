// OutsideFill: the pixels outside the segmented area are set on a new buffer and when the
// area moves, and left as they are on a buffer kept with the same area.
#include "outside_fill.h"

#include <cstdint>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "tilth/message_pool.h"

namespace tilth::segmentation {
namespace {

const cv::Rect kArea(2, 3, 4, 5);

// The pixels of `image` outside `area` equal to `value`.
int outside_equal(const cv::Mat& image, const cv::Rect& area, std::uint8_t value) {
  cv::Mat outside = image == value;
  outside(area).setTo(0);
  return cv::countNonZero(outside);
}

constexpr int kOutside = 10 * 12 - 4 * 5;

TEST(OutsideFill, FillsANewBufferAroundTheAreaOnly) {
  OutsideFill fill;
  cv::Mat image;
  reuse_or_create(image, 10, 12, CV_8UC1);
  image.setTo(7);
  fill.fill(image, nullptr, kArea, 128);
  EXPECT_EQ(outside_equal(image, kArea, 128), kOutside);
  EXPECT_EQ(cv::countNonZero(image(kArea) == 7), kArea.area());
}

TEST(OutsideFill, LeavesAKeptBufferFilledForTheSameAreaAlone) {
  OutsideFill fill;
  cv::Mat image(10, 12, CV_8UC1, cv::Scalar(0));
  fill.fill(image, nullptr, kArea, 128);
  image.at<std::uint8_t>(0, 0) = 1;  // would be 128 again if it were filled
  fill.fill(image, image.data, kArea, 128);
  EXPECT_EQ(image.at<std::uint8_t>(0, 0), 1);
  EXPECT_EQ(outside_equal(image, kArea, 128), kOutside - 1);
}

TEST(OutsideFill, FillsAgainWhenTheAreaMoves) {
  OutsideFill fill;
  cv::Mat image(10, 12, CV_8UC1, cv::Scalar(0));
  fill.fill(image, nullptr, kArea, 128);
  image.setTo(0);
  const cv::Rect moved(1, 1, 3, 3);
  fill.fill(image, image.data, moved, 128);
  EXPECT_EQ(outside_equal(image, moved, 128), 10 * 12 - 9);
}

TEST(OutsideFill, FillsABufferThatWasNotKept) {
  OutsideFill fill;
  cv::Mat image(10, 12, CV_8UC1, cv::Scalar(0));
  fill.fill(image, nullptr, kArea, 128);
  image.setTo(0);
  // The same address, but reuse_or_create allocated it anew (a sink kept the old one).
  static const std::uint8_t other = 0;
  fill.fill(image, &other, kArea, 128);
  EXPECT_EQ(outside_equal(image, kArea, 128), kOutside);
}

TEST(OutsideFill, SetsNanOutsideAFloatImage) {
  OutsideFill fill;
  cv::Mat depth(10, 12, CV_32FC1, cv::Scalar(500));
  fill.fill(depth, nullptr, kArea, std::numeric_limits<float>::quiet_NaN());
  EXPECT_EQ(cv::countNonZero(depth == depth), kArea.area());  // NaN != NaN
}

}  // namespace
}  // namespace tilth::segmentation
