// SoilSurface's residue height on planes with Gaussian depth noise of a known sigma:
// height_mm on quiet depth, 1.7 standard deviations of the 3x3 median's noise (0.714 of
// the depth's) on noisier depth, never above max_height_mm.
#include "soil_surface/soil_surface.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "synthetic_ground.h"

namespace tilth::segmentation {
namespace {

double residue_height_mm(const SoilSurface& surface, double sigma_mm) {
  // The chain's region, 320x240.
  const cv::Mat depth = testing::noisy_tilted_plane({320, 240}, sigma_mm, 7);
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
