// depth_noise_mm on planes with Gaussian noise of a known sigma, with the edges and holes
// a field's depth image has.
#include "depth_noise/depth_noise.h"

#include <cmath>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "synthetic_ground.h"

namespace tilth {
namespace {

const cv::Rect kRegion(160, 120, 320, 240);  // the middle half of 640x480

cv::Mat noisy_plane(double sigma_mm) {
  return testing::noisy_tilted_plane({640, 480}, sigma_mm, 5);
}

// The estimate's own spread: the median of about 19 000 differences is within 1.3 % (two
// standard errors, 1.25 / sqrt(n) relative), the 0.1 mm bins add up to 0.05 mm.
TEST(DepthNoise, IsTheNoisesStandardDeviation) {
  for (const double sigma : {3.0, 5.0, 8.0}) {
    EXPECT_NEAR(depth_noise_mm(noisy_plane(sigma), kRegion, 1.0f), sigma, 0.015 * sigma + 0.05)
        << "sigma " << sigma;
  }
}

// Noise at most the floor gives the floor, found by the count alone.
TEST(DepthNoise, AQuietFrameGivesTheFloor) {
  EXPECT_EQ(depth_noise_mm(noisy_plane(1.0), kRegion, 2.5f), 2.5f);
}

// Straw edges 30 mm high every 20 px, so that 10 % of the pairs straddle one, move the
// median of |d| to the 0.556 quantile of the other pairs' (0.5 / 0.9): 1.135 sigma, where
// the noise's own median is 0.674 sigma times sqrt 2. Every third pixel without depth (NaN
// or 0) changes nothing but the count.
TEST(DepthNoise, EdgesRaiseItByTheirShareHolesDoNot) {
  cv::Mat depth = noisy_plane(5.0);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      if (u % 40 < 20) depth.at<float>(v, u) -= 30.0f;
      if ((u + v) % 3 == 0) depth.at<float>(v, u) = v % 2 == 0 ? NAN : 0.0f;
    }
  }
  EXPECT_NEAR(depth_noise_mm(depth, kRegion, 1.0f), 1.135 * 5.0, 0.015 * 5.7 + 0.05);
}

// Infinite depths (a saturated or overflowing conversion) are no depth either; once they
// indexed the histogram out of bounds. Differences over 100 mm share its last bin.
TEST(DepthNoise, InfiniteDepthsAreNoDepth) {
  cv::Mat depth = noisy_plane(5.0);
  const cv::Mat clean = depth.clone();
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = v % 3; u < depth.cols; u += 3) {
      depth.at<float>(v, u) = u % 2 == 0 ? INFINITY : -INFINITY;
    }
  }
  depth.at<float>(kRegion.y, kRegion.x + 1) = 3e38f;
  const float noise = depth_noise_mm(depth, kRegion, 1.0f);
  EXPECT_NEAR(noise, depth_noise_mm(clean, kRegion, 1.0f), 0.05 * 5.0);
}

TEST(DepthNoise, TooFewPairsGiveZero) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(NAN));
  depth(cv::Rect(200, 200, 10, 4)).setTo(518.0f);  // 8 pairs on one sampled row
  EXPECT_EQ(depth_noise_mm(depth, kRegion, 1.0f), 0.0f);
}

}  // namespace
}  // namespace tilth
