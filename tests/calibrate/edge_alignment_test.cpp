// The check's estimator on drawn scenes with a known misalignment: discs nearer than the
// soil in the depth, the same discs brighter than the soil in the colour, moved by a
// known shift; with and without the shadows the discs cast.
#include "edge_alignment.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "edge_maps.h"

namespace tilth::calibrate {
namespace {

constexpr float kSoilMm = 518.0f;
constexpr float kDiscMm = 500.0f;

struct Scene {
  cv::Mat depth_mm;
  cv::Mat bgr;
};

// 40 discs of 6 to 20 px radius; in the colour moved by `shift`, and with a shadow of
// each disc `shadow` further on when that is not zero (drawn first, so the disc covers
// its own part).
Scene draw_scene(cv::Point shift, cv::Point shadow) {
  Scene scene{cv::Mat(480, 640, CV_32FC1, cv::Scalar(kSoilMm)),
              cv::Mat(480, 640, CV_8UC3, cv::Scalar(60, 70, 90))};
  cv::RNG rng(7);
  std::vector<std::pair<cv::Point, int>> discs;
  for (int i = 0; i < 40; ++i) {
    discs.push_back({{rng.uniform(40, 600), rng.uniform(40, 440)}, rng.uniform(6, 20)});
  }
  for (const auto& [centre, radius] : discs) {
    cv::circle(scene.depth_mm, centre, radius, cv::Scalar(kDiscMm), cv::FILLED);
    if (shadow != cv::Point()) {
      cv::circle(scene.bgr, centre + shift + shadow, radius, cv::Scalar(20, 25, 30), cv::FILLED);
    }
  }
  for (const auto& [centre, radius] : discs) {
    cv::circle(scene.bgr, centre + shift, radius, cv::Scalar(120, 200, 220), cv::FILLED);
  }
  return scene;
}

ShiftedDistances distances_of(const Scene& scene, NearSide side) {
  const cv::Mat region(scene.bgr.size(), CV_8UC1, cv::Scalar(255));
  ShiftedDistances distances;
  distances.add_frame(depth_edges(scene.depth_mm),
                      DirectedDistances(color_edges(scene.bgr, region)), side);
  return distances;
}

cv::Point2d measured_offset(const Scene& scene, NearSide side) {
  return distances_of(scene, side).best_offset();
}

TEST(EdgeAlignment, AlignedEdgesGiveNoOffset) {
  const cv::Point2d offset = measured_offset(draw_scene({0, 0}, {}), NearSide::kBrighter);
  // A step marks the depth pixels either side and Canny one of them, on a tie of the
  // gradients the left or upper one: the lines lie within half a pixel of each other.
  // Measured (-0.21, -0.21).
  EXPECT_NEAR(offset.x, 0.0, 0.5);
  EXPECT_NEAR(offset.y, 0.0, 0.5);
}

TEST(EdgeAlignment, AShiftedColourIsFoundWhereItWasMoved) {
  const cv::Point2d aligned = measured_offset(draw_scene({0, 0}, {}), NearSide::kBrighter);
  const cv::Point2d offset = measured_offset(draw_scene({4, -3}, {}), NearSide::kBrighter);
  // Measured 4.000 and -3.000 from the aligned offset.
  EXPECT_NEAR(offset.x - aligned.x, 4.0, 0.25);
  EXPECT_NEAR(offset.y - aligned.y, -3.0, 0.25);
}

TEST(EdgeAlignment, ShadowsBesideTheDiscsDoNotPullTheMatch) {
  // The shadow's outer edge is parallel to the disc's, 3 px further on, but darker
  // outside-in: of the other polarity, so not matched with the disc's depth edge.
  // Measured: the same offset to 0.001 px.
  const ShiftedDistances plain = distances_of(draw_scene({4, -3}, {}), NearSide::kBrighter);
  const ShiftedDistances shaded = distances_of(draw_scene({4, -3}, {3, 3}), NearSide::kBrighter);
  EXPECT_NEAR(shaded.best_offset().x, plain.best_offset().x, 0.25);
  EXPECT_NEAR(shaded.best_offset().y, plain.best_offset().y, 0.25);
  // At the shadows' own shift the depth edges find no more to match than without them:
  // the shadows' edges were not taken for the discs'.
  EXPECT_NEAR(shaded.cost({7, 0}), plain.cost({7, 0}), 0.05 * plain.cost({7, 0}));
  // Taken as the other polarity, they would be: the darker side's cost there drops.
  const ShiftedDistances plain_darker = distances_of(draw_scene({4, -3}, {}), NearSide::kDarker);
  const ShiftedDistances shaded_darker =
      distances_of(draw_scene({4, -3}, {3, 3}), NearSide::kDarker);
  EXPECT_LT(shaded_darker.cost({7, 0}), 0.8 * plain_darker.cost({7, 0}));
}

TEST(EdgeAlignment, TheWrongPolarityMatchesWorse) {
  const Scene scene = draw_scene({0, 0}, {});
  const cv::Mat region(scene.bgr.size(), CV_8UC1, cv::Scalar(255));
  const DirectedDistances color(color_edges(scene.bgr, region));
  ShiftedDistances brighter;
  ShiftedDistances darker;
  brighter.add_frame(depth_edges(scene.depth_mm), color, NearSide::kBrighter);
  darker.add_frame(depth_edges(scene.depth_mm), color, NearSide::kDarker);
  EXPECT_LT(brighter.cost(brighter.best_shift()), 0.5 * darker.cost(darker.best_shift()));
  EXPECT_GT(brighter.contrast(), 0.5);
}

TEST(EdgeAlignment, EdgeSectorsTurnFromPlusUTowardsPlusV) {
  EXPECT_EQ(edge_sector(1.0, 0.0), 1);
  EXPECT_EQ(edge_sector(1.0, 1.0), 2);
  EXPECT_EQ(edge_sector(0.0, 1.0), 3);
  EXPECT_EQ(edge_sector(-1.0, 0.0), 5);
  EXPECT_EQ(edge_sector(0.0, -1.0), 7);
  EXPECT_EQ(edge_sector(1.0, -0.1), 1);
}

}  // namespace
}  // namespace tilth::calibrate
