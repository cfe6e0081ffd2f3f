// The rules by which `tilth calibrate capture` keeps a frame pair as a view, on corners
// laid out by the test: still for three frames, not twice in one stop, not placed like a
// kept view, and the board's placement measured as ROS's camera_calibration measures it.
#include <cmath>

#include <gtest/gtest.h>

#include "view_selector.h"

namespace tilth::calibrate {
namespace {

const cv::Size kBoard{8, 5};
const cv::Size kImage{1280, 1024};

// A board's corners, `spacing` px apart, its first corner at `origin`, its columns sheared
// sideways by `shear` px per row.
std::vector<cv::Point2f> grid(cv::Point2f origin, float spacing, float shear = 0.0f) {
  std::vector<cv::Point2f> corners;
  for (int row = 0; row < kBoard.height; ++row) {
    for (int col = 0; col < kBoard.width; ++col) {
      corners.emplace_back(origin.x + col * spacing + row * shear, origin.y + row * spacing);
    }
  }
  return corners;
}

BoardSighting sighting(cv::Point2f origin, float spacing = 60.0f) {
  return {grid(origin * 0.5f, spacing * 0.5f), grid(origin, spacing)};
}

SelectorOptions options() {
  SelectorOptions options;
  options.inner_corners = kBoard;
  options.color_image = kImage;
  return options;
}

using Verdict = ViewSelector::Verdict;

TEST(BoardPlacement, ASquareBoardInTheMiddle) {
  // 7 x 4 spacings of 60 px: 420 x 240 px, in the middle of the image.
  const auto corners = grid({640.0f - 210.0f, 512.0f - 120.0f}, 60.0f);
  const BoardPlacement placement = placement_of(corners, kBoard, kImage);
  const double area = 420.0 * 240.0;
  EXPECT_NEAR(placement.size, std::sqrt(area / (1280.0 * 1024.0)), 1e-9);
  EXPECT_NEAR(placement.x, 0.5, 1e-9);
  EXPECT_NEAR(placement.y, 0.5, 1e-9);
  EXPECT_NEAR(placement.skew, 0.0, 1e-9);
}

TEST(BoardPlacement, SkewIsTwiceTheAngleFromARightAngle) {
  // Rows shifted 15 px per 60 px row: the angle at the first row's last corner is
  // 90 - atan(15/60) degrees.
  const auto corners = grid({300.0f, 300.0f}, 60.0f, 15.0f);
  EXPECT_NEAR(placement_of(corners, kBoard, kImage).skew, 2.0 * std::atan(15.0 / 60.0), 1e-6);
}

TEST(BoardPlacement, AtTheImagesEdgesXAndYAreNearZeroAndOne) {
  // Not exactly: x and y count from the board's middle less half the root of its area,
  // and this board is wider than high. x at the left edge: (210 - 317.5 / 2) / (1280 -
  // 317.5) = 0.053.
  const auto top_left = grid({0.0f, 0.0f}, 60.0f);
  const auto bottom_right = grid({1280.0f - 420.0f, 1024.0f - 240.0f}, 60.0f);
  const double border = std::sqrt(420.0 * 240.0);
  EXPECT_NEAR(placement_of(top_left, kBoard, kImage).x, (210.0 - border / 2) / (1280 - border),
              1e-6);
  EXPECT_NEAR(placement_of(top_left, kBoard, kImage).y, 0.0, 1e-6);  // 120 < border / 2
  EXPECT_GT(placement_of(bottom_right, kBoard, kImage).x, 0.9);
  EXPECT_NEAR(placement_of(bottom_right, kBoard, kImage).y, 1.0, 1e-6);
}

TEST(ViewSelector, KeepsTheThirdStillFrameOnceAStop) {
  ViewSelector selector(options());
  EXPECT_EQ(selector.consider(sighting({300, 300})).verdict, Verdict::kSettling);
  EXPECT_EQ(selector.consider(sighting({300.5f, 300})).verdict, Verdict::kSettling);
  const auto kept = selector.consider(sighting({300, 300.5f}));
  EXPECT_EQ(kept.verdict, Verdict::kKeep) << kept.reason;
  const auto again = selector.consider(sighting({300, 300}));
  EXPECT_EQ(again.verdict, Verdict::kSeenBefore);
  EXPECT_EQ(again.reason, "view kept already; move the board");
  EXPECT_EQ(selector.kept().size(), 1u);
}

TEST(ViewSelector, AMoveBeyondStillPxStartsTheCountAgain) {
  ViewSelector selector(options());
  selector.consider(sighting({300, 300}));
  selector.consider(sighting({300, 300}));
  // 1.2 px in the colour image, 0.6 in the ToF image: over the 1 px allowed.
  const auto moved = selector.consider(sighting({301.2f, 300}));
  EXPECT_EQ(moved.verdict, Verdict::kMoving);
  EXPECT_EQ(moved.reason, "board moving (1.2 px since the last frame)");
  EXPECT_EQ(selector.consider(sighting({301.2f, 300})).verdict, Verdict::kSettling);
  EXPECT_EQ(selector.consider(sighting({301.2f, 300})).verdict, Verdict::kKeep);
}

TEST(ViewSelector, APlacementLikeAKeptViewIsNotKeptAgain) {
  ViewSelector selector(options());
  for (int i = 0; i < 3; ++i) selector.consider(sighting({300, 300}));
  selector.consider(sighting({700, 300}));  // moved away
  // Back 40 px from the kept view: x differs by 40 / (1280 - border) = 0.046 < 0.2.
  for (int i = 0; i < 2; ++i) selector.consider(sighting({340, 300}));
  const auto like = selector.consider(sighting({340, 300}));
  EXPECT_EQ(like.verdict, Verdict::kSeenBefore);
  EXPECT_EQ(like.reason.rfind("placed like view 0 (", 0), 0u) << like.reason;
  // 400 px to the right: x differs by 0.4.
  selector.consider(sighting({700, 300}));
  selector.consider(sighting({700, 300}));
  EXPECT_EQ(selector.consider(sighting({700, 300})).verdict, Verdict::kKeep);
  EXPECT_EQ(selector.kept().size(), 2u);
}

TEST(ViewSelector, SaysWhichImageLacksTheBoard) {
  ViewSelector selector(options());
  BoardSighting no_color = sighting({300, 300});
  no_color.color.clear();
  BoardSighting no_depth = sighting({300, 300});
  no_depth.depth.clear();
  EXPECT_EQ(selector.consider(no_color).reason, "board not found in the colour image");
  EXPECT_EQ(selector.consider(no_depth).reason, "board not found in the ToF intensity");
  EXPECT_EQ(selector.consider({}).reason, "board not found in either image");
  // A board lost and found again settles from the start.
  selector.consider(sighting({300, 300}));
  selector.consider(no_color);
  EXPECT_EQ(selector.consider(sighting({300, 300})).verdict, Verdict::kSettling);
  EXPECT_EQ(selector.consider(sighting({300, 300})).verdict, Verdict::kSettling);
  EXPECT_EQ(selector.consider(sighting({300, 300})).verdict, Verdict::kKeep);
}

}  // namespace
}  // namespace tilth::calibrate
