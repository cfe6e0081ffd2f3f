// SoilSurface's residue height on planes with Gaussian depth noise of a known sigma:
// height_mm on quiet depth, 1.7 standard deviations of the 3x3 median's noise (0.714 of
// the depth's) on noisier depth, never above max_height_mm. And the height above the
// farthest plane beside the envelope, on a plane with a raised block wider than it.
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

// A tilted plane (quiet depth) with a block 10 mm nearer over its right third, wider than
// the envelope's window: the envelope follows the block, so its top is at the surface's
// level (height about 0), while the plane through the farthest depths stays on the ground
// and the block stands 10 mm above it. Within 0.5 mm: the plane is fitted to exact depths
// and the block's edges are left out.
TEST(SoilSurface, ThePlaneBesideTheEnvelopeStaysOnTheFarthestGround) {
  cv::Mat depth = testing::noisy_tilted_plane({320, 240}, 0.0, 7);
  const cv::Rect block(220, 0, 100, 240);
  depth(block) -= 10.0;
  const cv::Mat missing(depth.size(), CV_8UC1, cv::Scalar(0));
  const cv::Mat candidates(depth.size(), CV_8UC1, cv::Scalar(255));
  cv::Mat height, plane_height;
  SoilSurface(3.0, 3.0, 3.0, 40.0).heights(depth, missing, candidates, height, plane_height);
  const cv::Rect on_block(240, 20, 60, 200), on_ground(20, 20, 160, 200);
  EXPECT_NEAR(cv::mean(height(on_block))[0], 0.0, 0.5);
  EXPECT_NEAR(cv::mean(plane_height(on_block))[0], 10.0, 0.5);
  EXPECT_NEAR(cv::mean(plane_height(on_ground))[0], 0.0, 0.5);
}

}  // namespace
}  // namespace tilth::segmentation
