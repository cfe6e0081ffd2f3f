// SoilSurface's residue height on planes with Gaussian depth noise of a known sigma:
// height_mm on quiet depth, 1.7 standard deviations of the 3x3 median's noise (0.714 of
// the depth's) on noisier depth, never above max_height_mm.
#include "soil_surface/soil_surface.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

namespace tilth::segmentation {
namespace {

// The chain's region, 320x240, of a plane 518 mm away tilted 5 degrees along the rows.
cv::Mat noisy_plane(double sigma_mm) {
  cv::Mat depth(240, 320, CV_32FC1);
  for (int v = 0; v < depth.rows; ++v) {
    for (int u = 0; u < depth.cols; ++u) {
      depth.at<float>(v, u) = static_cast<float>(518.0 + 0.09 * (u - 160));
    }
  }
  cv::Mat noise(depth.size(), CV_32FC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma_mm);
  return depth + noise;
}

double residue_height_mm(const SoilSurface& surface, double sigma_mm) {
  const cv::Mat depth = noisy_plane(sigma_mm);
  const cv::Mat missing(depth.size(), CV_8UC1, cv::Scalar(0));
  const cv::Mat candidates(depth.size(), CV_8UC1, cv::Scalar(255));
  cv::Mat height;
  return surface.heights(depth, missing, candidates, height);
}

// The noise is measured within 1.5 % + 0.05 mm (depth_noise_test.cpp): 0.1 mm at 5 mm.
TEST(SoilSurface, TheResidueHeightFollowsTheDepthsNoiseUpToItsMaximum) {
  const SoilSurface surface(3.0, 4.0, 3.0, 0.0);
  EXPECT_DOUBLE_EQ(residue_height_mm(surface, 0.5), 3.0);
  EXPECT_DOUBLE_EQ(residue_height_mm(surface, 4.0), 3.0);  // 2.86 mm
  EXPECT_NEAR(residue_height_mm(surface, 5.0), 1.7 * 0.42 * 5.0, 0.1);
  EXPECT_DOUBLE_EQ(residue_height_mm(surface, 8.0), 4.0);  // 5.7 mm
}

TEST(SoilSurface, AMaximumAtTheHeightKeepsItFixed) {
  EXPECT_DOUBLE_EQ(residue_height_mm(SoilSurface(3.0, 3.0, 3.0, 0.0), 8.0), 3.0);
  EXPECT_DOUBLE_EQ(residue_height_mm(SoilSurface(3.0, 2.0, 3.0, 0.0), 8.0), 3.0);
}

}  // namespace
}  // namespace tilth::segmentation
