// segmentation.depth_aided and segmentation.fusion on painted frames whose heights are
// known: straw of the soil's colour on tilted ground, relief the soil surface must
// follow, a pile with no soil in reach, and the fusion's rule (one cue is enough for
// residue, both are needed for soil).
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "painted_frame.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;

const cv::Size kSize(160, 120);
const cv::Vec3b kSoil(55, 80, 110);
const cv::Vec3b kWetStraw(34, 53, 72);  // docs/segmentation.md: taken for soil by colour
const cv::Vec3b kStraw(120, 190, 220);
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Ground 500 mm away, sloping by 0.05 mm per pixel across and 0.03 down (about 3 and
// 2 degrees at 1 mm per pixel), with `relief_mm` of sinusoidal relief 80 px long, and
// `noise_mm` of depth noise.
PaintedFrame tilted_ground(const cv::Vec3b& colour, double relief_mm = 0.0, double noise_mm = 0.5) {
  PaintedFrame frame(kSize, colour, 0.0f);
  cv::RNG rng(11);
  for (int v = 0; v < kSize.height; ++v) {
    for (int u = 0; u < kSize.width; ++u) {
      const double relief = relief_mm * std::sin(2 * CV_PI * u / 80.0);
      frame.depth->mm.at<float>(v, u) =
          static_cast<float>(500.0 + 0.05 * u + 0.03 * v - relief + rng.gaussian(noise_mm));
    }
  }
  return frame;
}

// Lays a straw `height_mm` thick on the ground under `area`.
void lay_straw(PaintedFrame& frame, const cv::Rect& area, const cv::Vec3b& colour,
               double height_mm) {
  frame.paint(area, colour);
  frame.depth->mm(area) -= height_mm;
}

// Apart from one another: where two straws cross, the 3x3 median fills the inner corners.
const std::vector<cv::Rect> kStraws = {
    {10, 10, 120, 5}, {20, 40, 5, 70}, {40, 60, 50, 4}, {100, 20, 4, 90}};

cv::Mat straw_truth() {
  cv::Mat truth(kSize, CV_8UC1, cv::Scalar(0));
  for (const auto& straw : kStraws) truth(straw).setTo(255);
  return truth;
}

json exact(json params = json::object()) {
  params["dilation_px"] = 0;
  params["speckle_px"] = 0;
  return params;
}

// depth_aided's residue on `frame` (exact `params`): how many straw pixels it holds, and
// how many soil pixels.
std::pair<int, int> straws_found(const PaintedFrame& frame, const json& params) {
  const Segmented out = segment(describe_depth_aided(), exact(params), frame);
  const cv::Mat residue = out.mask == ResidueMask::kResidue;
  const cv::Mat truth = straw_truth();
  return {cv::countNonZero(residue & truth), cv::countNonZero(residue & ~truth)};
}

TEST(DepthAided, FindsSoilColouredStrawOnTiltedGround) {
  PaintedFrame frame = tilted_ground(kSoil);
  for (const auto& straw : kStraws) lay_straw(frame, straw, kWetStraw, 5.0);
  const Segmented out = segment(describe_depth_aided(), exact(), frame);
  // The 3x3 median keeps a straw's full height from its second pixel in: only the
  // outermost ring of each straw may read lower, and no soil pixel reads 3 mm high
  // (six standard deviations of the median's noise).
  cv::Mat found = out.mask == ResidueMask::kResidue;
  EXPECT_EQ(cv::countNonZero(found & ~straw_truth()), 0);
  cv::Mat cores(kSize, CV_8UC1, cv::Scalar(0));
  for (const auto& straw : kStraws) cores(straw - cv::Size(2, 2) + cv::Point(1, 1)).setTo(255);
  EXPECT_EQ(cv::countNonZero(cores & ~found), 0);
}

// Relief of +-2.5 mm, 80 px long, with straws 6 mm thick on it. No plane fits it: the
// fitted one lies about 1 mm below the middle (the soil in the troughs must not lie
// beyond it), so the crest tops stand more than 3 mm above it and are taken for residue
// (about a tenth of the soil). The local surface follows the relief: no soil is taken
// for residue, and every straw is found but for its corners, which the 3x3 median rounds
// off (4 px per straw).
TEST(DepthAided, LocalSurfaceFollowsReliefThatAPlaneCannot) {
  PaintedFrame frame = tilted_ground(kSoil, 2.5);
  for (const auto& straw : kStraws) lay_straw(frame, straw, kWetStraw, 6.0);
  const auto [local_hits, local_false] = straws_found(frame, json::object());
  const auto [plane_hits, plane_false] = straws_found(frame, {{"surface_px", 0}});
  const int straw_pixels = cv::countNonZero(straw_truth());
  const int soil_pixels = kSize.area() - straw_pixels;
  EXPECT_GE(local_hits, straw_pixels - 4 * static_cast<int>(kStraws.size()));
  EXPECT_EQ(local_false, 0);
  EXPECT_GT(plane_false, 0.05 * soil_pixels);
}

// Depth three times as noisy as a ToF camera's on dark soil (7 mm): the 3x3 median's
// noise is about 2.9 mm, and a fixed 3 mm takes soil lifted by noise for residue, which
// leaves the farther soil (docs/accuracy.md): 28 % of it here. The residue height rises
// with the noise to its maximum, 4 mm, which takes 12 %; straws 8 mm thick are still
// found (81 % of their pixels, 93 % at 3 mm).
TEST(DepthAided, NoisyDepthRaisesTheResidueHeight) {
  PaintedFrame frame = tilted_ground(kSoil, 0.0, 7.0);
  for (const auto& straw : kStraws) lay_straw(frame, straw, kWetStraw, 8.0);
  const auto [risen_hits, risen_false] = straws_found(frame, json::object());
  const auto [fixed_hits, fixed_false] = straws_found(frame, {{"max_height_mm", 3}});
  const int straw_pixels = cv::countNonZero(straw_truth());
  const int soil_pixels = kSize.area() - straw_pixels;
  EXPECT_GT(fixed_false, 0.2 * soil_pixels);
  EXPECT_LT(risen_false, 0.5 * fixed_false);
  EXPECT_GT(risen_hits, 0.75 * straw_pixels);
  EXPECT_GT(fixed_hits, risen_hits);
}

// A pile: pieces of straw 8 px across at 20-60 mm above the ground, with the soil
// showing through 4x4 px gaps over about 1 % of the frame. The soil surface goes through
// the deepest points; the pile is residue, and too little soil is left for a measurement
// (estimation.ground_distance needs 5 %).
TEST(DepthAided, APileIsResidueNotASurface) {
  PaintedFrame frame = tilted_ground(kWetStraw);
  cv::RNG rng(5);
  for (int v = 0; v < kSize.height; v += 8) {
    for (int u = 0; u < kSize.width; u += 8) {
      frame.depth->mm(cv::Rect(u, v, 8, 8)) -= rng.uniform(20.0, 60.0);
    }
  }
  for (int gap = 0; gap < 12; ++gap) {
    const cv::Rect area(rng.uniform(0, kSize.width - 4), rng.uniform(0, kSize.height - 4), 4, 4);
    frame.depth->mm(area) = tilted_ground(kSoil).depth->mm(area);
  }
  const Segmented out = segment(describe_depth_aided(), {}, frame);
  EXPECT_LT(count_equal(out.mask, ResidueMask::kSoil), 0.05 * kSize.area());
}

TEST(DepthAided, OnlyMissingDepthIsUnknown) {
  PaintedFrame frame = tilted_ground(kSoil);
  frame.color->status.setTo(RegisteredColor::kOutsideColor);  // colour is not used
  frame.depth->mm.at<float>(50, 50) = kNaN;
  frame.depth->mm.at<float>(60, 60) = -23.9f;  // behind the mounting surface
  const Segmented out = segment(describe_depth_aided(), exact(), frame);
  EXPECT_EQ(out.mask.at<std::uint8_t>(50, 50), ResidueMask::kUnknown);
  EXPECT_EQ(out.mask.at<std::uint8_t>(60, 60), ResidueMask::kUnknown);
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kSoil), kSize.area() - 2);
}

// The fusion's table: dry straw flat on the soil (colour only), wet straw on it (height
// only), and what each cue cannot tell.
TEST(Fusion, OneCueIsEnoughForResidueBothAreNeededForSoil) {
  PaintedFrame frame = tilted_ground(kSoil);
  const cv::Rect pressed(10, 10, 30, 30);      // dry straw pressed flat: colour says residue
  const cv::Rect wet(50, 10, 30, 30);          // wet straw 6 mm high: height says residue
  const cv::Rect hidden_high(90, 10, 30, 30);  // colour unknown, 6 mm high
  const cv::Rect hidden_low(90, 60, 30, 30);   // colour unknown, on the soil
  const cv::Rect no_depth(10, 60, 30, 30);
  frame.paint(pressed, kStraw);
  lay_straw(frame, wet, kWetStraw, 6.0);
  lay_straw(frame, hidden_high, cv::Vec3b(0, 0, 0), 6.0);
  frame.color->status(hidden_high).setTo(RegisteredColor::kOccluded);
  frame.paint(hidden_low, cv::Vec3b(0, 0, 0));
  frame.color->status(hidden_low).setTo(RegisteredColor::kOccluded);
  frame.depth->mm(no_depth).setTo(kNaN);

  const Segmented out = segment(describe_fusion(), exact({{"smoothing_px", 0}}), frame);
  EXPECT_EQ(count_equal(out.mask(pressed), ResidueMask::kResidue), pressed.area());
  // The 3x3 median leaves each corner of the wet straw with the soil's height, and its
  // colour is the soil's: the four corners are soil.
  EXPECT_EQ(count_equal(out.mask(wet), ResidueMask::kResidue), wet.area() - 4);
  // Residue for its neighbours, unknown itself: its colour is not trusted.
  EXPECT_EQ(count_equal(out.mask(hidden_high), ResidueMask::kUnknown), hidden_high.area());
  EXPECT_EQ(count_equal(out.mask(hidden_low), ResidueMask::kUnknown), hidden_low.area());
  EXPECT_EQ(count_equal(out.mask(no_depth), ResidueMask::kUnknown), no_depth.area());
  const int soil = kSize.area() - pressed.area() - (wet.area() - 4) - hidden_high.area() -
                   hidden_low.area() - no_depth.area();
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kSoil), soil);
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), pressed.area() + wet.area() - 4);
}

// An occluded pixel that stands high still makes its neighbours straw edges.
TEST(Fusion, HighPixelWithUntrustedColourGrowsIntoItsNeighbours) {
  PaintedFrame frame = tilted_ground(kSoil);
  const cv::Rect hidden(70, 50, 8, 8);
  lay_straw(frame, hidden, cv::Vec3b(0, 0, 0), 6.0);
  frame.color->status(hidden).setTo(RegisteredColor::kOccluded);
  const Segmented out = segment(describe_fusion(), {{"dilation_px", 2}, {"speckle_px", 0}}, frame);
  EXPECT_EQ(count_equal(out.mask(hidden), ResidueMask::kUnknown), hidden.area());
  for (const cv::Point edge : {cv::Point(68, 54), cv::Point(69, 54), cv::Point(79, 53)}) {
    EXPECT_EQ(out.mask.at<std::uint8_t>(edge), ResidueMask::kResidue) << edge;
  }
  for (const cv::Point beyond : {cv::Point(67, 54), cv::Point(80, 53)}) {
    EXPECT_EQ(out.mask.at<std::uint8_t>(beyond), ResidueMask::kSoil) << beyond;
  }
}

}  // namespace
}  // namespace tilth::segmentation
