// ResidueIndex's smoothing on noisy colours: a frame of dark soil beside shadowed straw
// (the colours of docs/segmentation.md in shadow), with the sensor noise of a camera at
// low gain (2 DN) and at a high one (6 DN); and the spread of an index of known median and
// standard deviation.
#include "residue_index.h"

#include <limits>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

namespace tilth::segmentation {
namespace {

const cv::Size kSize(160, 120);
const cv::Vec3b kShadowedStraw(60, 95, 110);  // exg 0.075
const cv::Vec3b kShadowedSoil(27, 40, 55);    // exg -0.016
const cv::Rect kSoilHalf(0, 0, kSize.width / 2, kSize.height);
const cv::Rect kStrawHalf(kSize.width / 2, 0, kSize.width / 2, kSize.height);

cv::Mat soil_beside_straw(double noise_dn) {
  cv::Mat bgr(kSize, CV_8UC3);
  bgr(kSoilHalf).setTo(cv::Scalar(kShadowedSoil));
  bgr(kStrawHalf).setTo(cv::Scalar(kShadowedStraw));
  cv::Mat noise(kSize, CV_16SC3);
  cv::RNG rng(11);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, noise_dn);
  cv::Mat noisy;
  bgr.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(bgr, CV_8UC3);
  return bgr;
}

// Pixels on the wrong side, more than 3 px (the largest box's reach) from the boundary.
int misclassified(const cv::Mat& residue) {
  const int margin = 3;
  const cv::Rect soil(0, 0, kSoilHalf.width - margin, kSize.height);
  const cv::Rect straw(kStrawHalf.x + margin, 0, kStrawHalf.width - margin, kSize.height);
  return cv::countNonZero(residue(soil)) + straw.area() - cv::countNonZero(residue(straw));
}

struct Classified {
  IndexSplit split;
  cv::Mat residue;
};

Classified classify(const ResidueIndex& index, const cv::Mat& bgr) {
  Classified out;
  out.split = index.classify(bgr, cv::Mat::zeros(kSize, CV_8UC1), out.residue);
  return out;
}

// At 2 DN the index of a 3x3 box varies by about 0.013 on the dark soil, under 0.6 of
// exg's least gap (0.05): the box stays 3x3 and the mask is the fixed smoothing's.
TEST(ResidueIndex, KeepsItsSmoothingOnQuietColours) {
  const cv::Mat bgr = soil_beside_straw(2.0);
  const Classified adaptive = classify(ResidueIndex(ColorIndex::kExg, 1, 3), bgr);
  const Classified fixed = classify(ResidueIndex(ColorIndex::kExg, 1, 1), bgr);
  EXPECT_EQ(adaptive.split.smoothing_px, 1);
  EXPECT_EQ(cv::countNonZero(adaptive.residue != fixed.residue), 0);
}

// At 6 DN a dark soil pixel's exg varies by about 0.12, a 3x3 box's by 0.04, over the
// limit of 0.03, and a 5x5 box's by 0.024, under it: the colours are averaged over 5x5.
// Soil, about 0.045 below Otsu's threshold, then crosses it about 2 standard deviations
// out instead of 1.1: of the pixels judged, 1.6 % are on the wrong side instead of 9.7 %.
TEST(ResidueIndex, AveragesNoisyColoursOverALargerBox) {
  const cv::Mat bgr = soil_beside_straw(6.0);
  const Classified adaptive = classify(ResidueIndex(ColorIndex::kExg, 1, 3), bgr);
  const Classified fixed = classify(ResidueIndex(ColorIndex::kExg, 1, 1), bgr);
  EXPECT_EQ(adaptive.split.smoothing_px, 2);
  EXPECT_EQ(fixed.split.smoothing_px, 1);
  const int judged = kSize.area() - 2 * 3 * kSize.height;
  EXPECT_LT(misclassified(adaptive.residue), 0.02 * judged);
  EXPECT_GT(misclassified(fixed.residue), 0.08 * judged);
}

// A largest box no larger than the smoothing keeps the smoothing, however noisy.
TEST(ResidueIndex, AMaximumAtTheSmoothingKeepsIt) {
  const Classified fixed = classify(ResidueIndex(ColorIndex::kExg, 1, 0), soil_beside_straw(6.0));
  EXPECT_EQ(fixed.split.smoothing_px, 1);
}

// An exg image of Gaussian values (median 0.02, sigma 0.03), of which the left half is
// asked for, and a right half far off that must not count: the spread is read from a
// histogram of thousandths of exg's range of 1, so within 0.002 of the median and 5 % of
// the sigma (the sample's own error on 4800 pixels is about 2 %).
TEST(ResidueIndex, TheSpreadOfTheMarkedPixels) {
  cv::Mat index(kSize, CV_32FC1);
  cv::RNG(5).fill(index, cv::RNG::NORMAL, 0.02, 0.03);
  index(kStrawHalf).setTo(0.3);
  cv::Mat among = cv::Mat::zeros(kSize, CV_8UC1);
  among(kSoilHalf).setTo(255);
  const auto spread = ResidueIndex(ColorIndex::kExg, 1, 1).spread(index, among);
  ASSERT_TRUE(spread.has_value());
  EXPECT_NEAR(spread->median, 0.02, 0.002);
  EXPECT_NEAR(spread->sigma, 0.03, 0.0015);
}

// Pixels without a colour (NaN) do not count, and a spread needs kMinSpreadPixels of the
// sampled ones (every second pixel of every second row): a 20x20 patch has 100, an 18x18
// one 81.
TEST(ResidueIndex, NoSpreadFromTooFewPixels) {
  const ResidueIndex exg(ColorIndex::kExg, 1, 1);
  const cv::Mat all(kSize, CV_8UC1, cv::Scalar(255));
  for (const int side : {20, 18}) {
    cv::Mat index(kSize, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
    index(cv::Rect(0, 0, side, side)).setTo(0.01);
    EXPECT_EQ(exg.spread(index, all).has_value(), side == 20) << side << "x" << side;
  }
}

}  // namespace
}  // namespace tilth::segmentation
