// The colour indices' box sums against OpenCV's boxFilter, which they replace: on whole
// images (reflected at the edges) and on views that reach the image's edges or stay inside.
#include "box_sums.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

cv::Mat opencv_sums(const cv::Mat& bgr, int radius) {
  cv::Mat sums;
  const int side = 2 * radius + 1;
  cv::boxFilter(bgr, sums, CV_16U, {side, side}, {-1, -1}, false, cv::BORDER_REFLECT);
  return sums;
}

int differing_values(const cv::Mat& a, const cv::Mat& b) {
  EXPECT_EQ(a.type(), b.type());
  EXPECT_EQ(a.size(), b.size());
  cv::Mat differ;
  cv::compare(a.reshape(1), b.reshape(1), differ, cv::CMP_NE);
  return cv::countNonZero(differ);
}

TEST(BoxSums, AreOpenCvsUnnormalisedBoxFilterOnWholeImagesAndViews) {
  cv::Mat image(37, 53, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  const cv::Rect views[] = {{0, 0, 53, 37},  {5, 4, 40, 30}, {0, 3, 20, 34},
                            {40, 0, 13, 10}, {1, 1, 51, 35}, {52, 36, 1, 1}};
  for (int radius = 0; radius <= 3; ++radius) {
    for (const cv::Rect& view : views) {
      cv::Mat sums;
      box_sums(image(view), radius, sums);
      EXPECT_EQ(differing_values(sums, opencv_sums(image(view), radius)), 0)
          << "radius " << radius << ", view " << view;
    }
  }
}

TEST(BoxSums, TheLargestBoxOfWhiteFitsIn16Bits) {
  const cv::Mat white(9, 9, CV_8UC3, cv::Scalar::all(255));
  cv::Mat sums;
  box_sums(white, 3, sums);
  EXPECT_EQ(sums.at<cv::Vec3w>(4, 4), cv::Vec3w(49 * 255, 49 * 255, 49 * 255));
  EXPECT_EQ(sums.at<cv::Vec3w>(0, 0), cv::Vec3w(49 * 255, 49 * 255, 49 * 255));
}

TEST(BoxSums, RefuseWhatTheyCannotSum) {
  cv::Mat sums;
  EXPECT_THROW(box_sums(cv::Mat(4, 4, CV_8UC1), 1, sums), Error);
  EXPECT_THROW(box_sums(cv::Mat(4, 4, CV_8UC3), 4, sums), Error);
}

}  // namespace
}  // namespace tilth::segmentation
