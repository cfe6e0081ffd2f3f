// The step search of estimation.ground_plane (ground_steps.h): straight steps in any
// direction found with their height and line, and relief, short edges and low steps not
// taken for steps.
//
// The points: a disc of 200 mm radius sampled every 4.6 mm (every fourth point of the
// chain's grid at about 520 mm), levels with 0.6 mm of noise (the ToF's 1 mm after the
// segmentation's 3x3 median). A side of a piece of a line averages some 30 of them, so a
// piece's jump has a standard error of 0.15 mm.
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "ground_steps.h"

namespace tilth::estimation {
namespace {

constexpr double kReachMm = 200.0;
constexpr double kSpacingMm = 4.6;
constexpr double kNoiseMm = 0.6;
// A line's place is known to a strip.
constexpr double kStripToleranceMm = 4.0;

template <class Level>
std::vector<LevelPoint> ground(const Level& level, int seed = 1) {
  cv::RNG random(static_cast<std::uint64_t>(seed));
  std::vector<LevelPoint> points;
  for (double y = -kReachMm; y <= kReachMm; y += kSpacingMm) {
    for (double x = -kReachMm; x <= kReachMm; x += kSpacingMm) {
      if (std::hypot(x, y) > kReachMm) continue;
      points.push_back({x, y, level(x, y) + random.gaussian(kNoiseMm)});
    }
  }
  return points;
}

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// A step of `height_mm` whose line lies `at_mm` from the tool point, its normal at
// `angle_deg`: every direction, on and between the directions searched (every 15 deg).
TEST(GroundSteps, FindsAStraightStepInAnyDirection) {
  for (const double angle_deg : {0.0, 20.0, 52.5, 95.0, 142.0, 171.0}) {
    const double c = std::cos(radians(angle_deg)), s = std::sin(radians(angle_deg));
    for (const double at_mm : {-60.0, 12.0, 35.0}) {
      const auto points =
          ground([&](double x, double y) { return x * c + y * s > at_mm ? 3.0 : 0.0; });
      const std::optional<GroundStep> step = highest_step(points, 2.0);
      if (!step) {
        ADD_FAILURE() << "no step at " << angle_deg << " deg, " << at_mm << " mm";
        continue;
      }
      // The jump of the weakest piece of the line searched nearest the step, which may
      // cross it a strip (4 mm) off in the outer pieces: at least three quarters of it.
      EXPECT_GE(std::abs(step->height_mm), 0.75 * 3.0 - 0.15) << angle_deg << " deg, " << at_mm;
      EXPECT_LE(std::abs(step->height_mm), 3.0 + 0.45) << angle_deg << " deg, " << at_mm;
      // The line cuts off the far level and keeps the tool's, 20 mm and more from the step
      // over the 100 mm around the tool point.
      for (double along = -50.0; along <= 50.0; along += 10.0) {
        for (const double off : {20.0, 40.0}) {
          const double x_far = (at_mm + off) * c - along * s, y_far = (at_mm + off) * s + along * c;
          const double x_near = (at_mm - off) * c - along * s;
          const double y_near = (at_mm - off) * s + along * c;
          const bool tool_beyond = at_mm < 0;
          EXPECT_NE(step->cuts_off(x_far, y_far), tool_beyond) << angle_deg << " deg, " << at_mm;
          EXPECT_EQ(step->cuts_off(x_near, y_near), tool_beyond) << angle_deg << " deg, " << at_mm;
        }
      }
    }
  }
}

// The soil of the simulator's rough field (six waves of 1.33 mm, 15-80 mm long, in any
// direction; std 2.3 mm, as the `field` preset), seeded ten ways: no step of 2 mm.
TEST(GroundSteps, ReliefIsNoStep) {
  for (int seed = 1; seed <= 10; ++seed) {
    cv::RNG random(static_cast<std::uint64_t>(100 + seed));
    struct Wave {
      double kx, ky, phase;
    };
    std::vector<Wave> waves;
    for (int i = 0; i < 6; ++i) {
      const double length = random.uniform(15.0, 80.0), angle = random.uniform(0.0, CV_PI);
      waves.push_back({2 * CV_PI / length * std::cos(angle), 2 * CV_PI / length * std::sin(angle),
                       random.uniform(0.0, 2 * CV_PI)});
    }
    const auto points = ground(
        [&](double x, double y) {
          double level = 0;
          for (const Wave& wave : waves)
            level += 4.0 / 3 * std::sin(wave.kx * x + wave.ky * y + wave.phase);
          return level;
        },
        seed);
    const std::optional<GroundStep> step = highest_step(points, 2.0);
    EXPECT_FALSE(step) << "seed " << seed << ": " << step->height_mm << " mm at " << step->at_mm;
  }
}

// A 4 mm edge 60 mm long (a clod, a wheel mark's end) is not a step across the ground;
// the same edge across the whole region is.
TEST(GroundSteps, AnEdgeAcrossPartOfTheGroundIsNoStep) {
  const auto short_edge =
      ground([](double x, double y) { return x > 30 && std::abs(y) < 30 ? 4.0 : 0.0; });
  EXPECT_FALSE(highest_step(short_edge, 2.0));
  const auto long_edge = ground([](double x, double) { return x > 30 ? 4.0 : 0.0; });
  EXPECT_TRUE(highest_step(long_edge, 2.0));
}

// A 4 mm step of which two 40 mm pieces jump by 0.5 mm only (residue the segmentation
// let through on one, a noisy side on another: at twice the simulator's ToF noise a piece
// of a 4 mm step measured 2.7 mm) is still a step: one piece in three may fail to show
// it. Half of the line failing is no step.
TEST(GroundSteps, OnePieceInThreeMayFailToShowAStep) {
  const auto spoiled = [](int pieces) {
    return [pieces](double x, double y) {
      const bool shows = y < -40 || y >= -40 + 40 * pieces;  // pieces from y = -40 on
      return x > 20 ? (shows ? 4.0 : 0.5) : 0.0;
    };
  };
  const std::optional<GroundStep> step = highest_step(ground(spoiled(2)), 2.0);
  ASSERT_TRUE(step);
  EXPECT_NEAR(step->at_mm, 20.0, kStripToleranceMm);
  EXPECT_GT(step->height_mm, 3.0);
  EXPECT_FALSE(highest_step(ground(spoiled(5)), 2.0));
}

TEST(GroundSteps, StepsLowerThanAskedAreNotFound) {
  const auto points = ground([](double x, double) { return x > 30 ? 1.5 : 0.0; });
  EXPECT_FALSE(highest_step(points, 2.0));
  const std::optional<GroundStep> lower = highest_step(points, 1.0);
  ASSERT_TRUE(lower);
  EXPECT_NEAR(lower->height_mm, 1.5, 0.4);
}

// A step through the tool point: the levels are residuals from a surface fitted on the
// tool's level, so the side whose level is near 0 is the tool's, and it is kept, on
// whichever side of the line the tool point's own strip falls.
TEST(GroundSteps, AStepThroughTheToolPointKeepsTheToolsLevel) {
  for (const double at_mm : {-1.0, 1.0}) {
    for (const double far_mm : {-3.0, 3.0}) {
      const auto points = ground([&](double x, double) { return x > at_mm ? 0.0 : far_mm; });
      const std::optional<GroundStep> step = highest_step(points, 2.0);
      ASSERT_TRUE(step) << at_mm << ", " << far_mm;
      EXPECT_TRUE(step->cuts_off(-20.0, 0.0)) << at_mm << ", " << far_mm;
      EXPECT_FALSE(step->cuts_off(20.0, 0.0)) << at_mm << ", " << far_mm;
    }
  }
}

// Points without a level (NaN) or a place are left out, not summed into the strips.
TEST(GroundSteps, PointsWithoutALevelOrPlaceAreLeftOut) {
  auto points = ground([](double x, double) { return x > 30 ? 3.0 : 0.0; });
  const std::optional<GroundStep> clean = highest_step(points, 2.0);
  ASSERT_TRUE(clean);
  for (std::size_t i = 0; i < points.size(); i += 7) points[i].level_mm = std::nan("");
  points.push_back({std::nan(""), 0.0, 0.0});
  points.push_back({std::numeric_limits<double>::infinity(), 0.0, 0.0});
  const std::optional<GroundStep> step = highest_step(points, 2.0);
  ASSERT_TRUE(step);
  EXPECT_NEAR(step->at_mm, clean->at_mm, kStripToleranceMm);
  EXPECT_NEAR(step->height_mm, clean->height_mm, 0.3);
  EXPECT_FALSE(highest_step(std::vector<LevelPoint>{}, 2.0));
}

// A ridge 20 mm high every 600 mm (the `ridges` preset) curves, but jumps nowhere: not
// even by 1 mm, whose line the ridge's flank (1.7 mm between neighbouring sides) would
// pass but for the flat sides a step needs.
TEST(GroundSteps, RidgesAreNoStep) {
  const auto points = ground([](double x, double y) {
    return 10.0 *
           std::sin(2 * CV_PI * (x * std::cos(radians(70)) + y * std::sin(radians(70))) / 600.0);
  });
  EXPECT_FALSE(highest_step(points, 1.0));
}

}  // namespace
}  // namespace tilth::estimation
