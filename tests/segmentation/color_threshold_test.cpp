// segmentation.color_threshold on synthetic scenes whose mask is known pixel for pixel:
// straw against soil in each colour space, the dilation at a mixed straw edge, unknowns,
// parameter errors and buffer reuse. Every comparison is exact: the stage classifies
// and copies, it computes no new depths.
#include "color_threshold.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/testing/stage_harness.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;
using testing::TransformHarness;

const cv::Size kSize(64, 48);
constexpr float kSoilDepthMm = 500.0f;
constexpr float kStrawDepthMm = 470.0f;  // straw lying 30 mm above the soil
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Reference colours (BGR) of docs/segmentation.md.
const cv::Vec3b kStraw(120, 190, 220);
const cv::Vec3b kSoil(55, 80, 110);

struct Scene {
  std::shared_ptr<RegisteredColor> color = std::make_shared<RegisteredColor>();
  std::shared_ptr<DepthImage> depth = std::make_shared<DepthImage>();

  // Soil everywhere, every colour trusted.
  Scene() {
    color->bgr = cv::Mat(kSize, CV_8UC3, cv::Scalar(kSoil));
    color->status = cv::Mat(kSize, CV_8UC1, cv::Scalar(RegisteredColor::kValid));
    depth->mm = cv::Mat(kSize, CV_32FC1, cv::Scalar(kSoilDepthMm));
  }
  void paint(const cv::Rect& area, const cv::Vec3b& bgr, float depth_mm) {
    color->bgr(area).setTo(cv::Scalar(bgr));
    depth->mm(area).setTo(depth_mm);
  }
};

struct Output {
  cv::Mat mask;
  cv::Mat soil_depth_mm;
};

Output segment(const Scene& scene, const json& params) {
  TransformHarness stage(describe_color_threshold(), params);
  const auto out = stage.run({scene.color, scene.depth});
  return {out[0].get<ResidueMask>().values, out[1].get<DepthImage>().mm};
}

int count_equal(const cv::Mat& mask, std::uint8_t value) { return cv::countNonZero(mask == value); }

int count_finite(const cv::Mat& depth_mm) {
  cv::Mat finite;
  cv::compare(depth_mm, depth_mm, finite, cv::CMP_EQ);  // false only for NaN
  return cv::countNonZero(finite);
}

std::string construction_error(const json& params) {
  try {
    TransformHarness stage(describe_color_threshold(), params);
  } catch (const Error& error) {
    return error.what();
  }
  return "constructed";
}

class EachColorSpace : public ::testing::TestWithParam<std::string> {};

TEST_P(EachColorSpace, DefaultsSeparateStrawFromSoilExactly) {
  Scene scene;
  const cv::Rect straw(0, 0, kSize.width / 2, kSize.height);
  scene.paint(straw, kStraw, kStrawDepthMm);

  const Output out = segment(scene, {{"color_space", GetParam()}, {"dilation_px", 0}});

  cv::Mat expected_mask(kSize, CV_8UC1, cv::Scalar(ResidueMask::kSoil));
  expected_mask(straw).setTo(ResidueMask::kResidue);
  EXPECT_EQ(cv::countNonZero(out.mask != expected_mask), 0);
  cv::Mat soil_mm =
      out.soil_depth_mm(cv::Rect(straw.width, 0, kSize.width - straw.width, kSize.height));
  EXPECT_EQ(cv::countNonZero(soil_mm != kSoilDepthMm), 0);
  EXPECT_EQ(count_finite(out.soil_depth_mm), soil_mm.rows * soil_mm.cols);
}

INSTANTIATE_TEST_SUITE_P(ColorThreshold, EachColorSpace, ::testing::Values("hsv", "lab", "bgr"),
                         [](const auto& info) { return info.param; });

// The defaults' documented behaviour on the reference colours of docs/segmentation.md.
struct ReferenceColor {
  const char* name;
  cv::Vec3b bgr;
  bool residue_in_hsv;
  bool residue_in_lab;
  bool residue_in_bgr;
};

TEST(ColorThreshold, DefaultsClassifyTheReferenceColoursAsDocumented) {
  const std::vector<ReferenceColor> colors = {
      {"straw", {120, 190, 220}, true, true, true},
      {"pale straw", {170, 215, 230}, true, true, true},
      {"golden straw", {60, 160, 200}, true, true, true},
      {"grey old straw", {130, 160, 170}, true, true, true},
      {"shadowed straw", {60, 95, 110}, true, true, false},
      {"straw in a straw's shadow", {44, 80, 94}, true, true, false},
      {"straw's shaded side in shadow", {26, 48, 56}, true, true, false},
      {"wet straw", {34, 53, 72}, false, false, false},
      {"brown soil", {55, 80, 110}, false, false, false},
      {"dark moist soil", {45, 55, 70}, false, false, false},
      {"dry light soil", {100, 125, 150}, false, false, false},
      {"reddish soil", {60, 85, 140}, false, false, false},
  };
  Scene scene;
  for (std::size_t i = 0; i < colors.size(); ++i) {
    scene.paint(cv::Rect(static_cast<int>(i) * 4, 0, 4, kSize.height), colors[i].bgr, kSoilDepthMm);
  }
  for (const std::string space : {"hsv", "lab", "bgr"}) {
    const Output out = segment(scene, {{"color_space", space}, {"dilation_px", 0}});
    for (std::size_t i = 0; i < colors.size(); ++i) {
      const bool expected = space == "hsv"   ? colors[i].residue_in_hsv
                            : space == "lab" ? colors[i].residue_in_lab
                                             : colors[i].residue_in_bgr;
      EXPECT_EQ(out.mask.at<std::uint8_t>(0, static_cast<int>(i) * 4),
                expected ? ResidueMask::kResidue : ResidueMask::kSoil)
          << colors[i].name << " in " << space;
    }
  }
}

// Bounds chosen around the soil colour instead: the classes swap, so the stage uses the
// configured range in the configured colour space, not its defaults.
struct ConfiguredRange {
  std::string space;
  json lower;
  json upper;
};

class ConfiguredRanges : public ::testing::TestWithParam<ConfiguredRange> {};

TEST_P(ConfiguredRanges, SelectTheConfiguredColour) {
  Scene scene;
  const cv::Rect straw(0, 0, kSize.width / 2, kSize.height);
  scene.paint(straw, kStraw, kStrawDepthMm);
  const auto& range = GetParam();

  const Output out = segment(scene, {{"color_space", range.space},
                                     {"residue_lower", range.lower},
                                     {"residue_upper", range.upper},
                                     {"dilation_px", 0}});

  EXPECT_EQ(count_equal(out.mask(straw), ResidueMask::kSoil), straw.area());
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), kSize.area() - straw.area());
  EXPECT_EQ(cv::countNonZero(out.soil_depth_mm(straw) != kStrawDepthMm), 0);
}

// The soil colour is hsv (14, 127, 110), lab (94, 137, 148), bgr (55, 80, 110).
INSTANTIATE_TEST_SUITE_P(ColorThreshold, ConfiguredRanges,
                         ::testing::Values(ConfiguredRange{"hsv", {10, 100, 90}, {16, 150, 130}},
                                           ConfiguredRange{"lab", {80, 130, 140}, {110, 145, 155}},
                                           ConfiguredRange{"bgr", {40, 60, 90}, {70, 100, 130}}),
                         [](const auto& info) { return info.param.space; });

// A 10x10 straw patch 30 mm above the soil, ringed by one pixel that mixes 20 % straw
// with 80 % soil in colour and in depth, as a ToF pixel straddling the straw edge does.
// The ring's colour (hsv hue 16) is soil, so only the dilation can keep its depth out.
const cv::Rect kStrawPatch(20, 20, 10, 10);
const cv::Rect kMixedRing(19, 19, 12, 12);
const cv::Vec3b kMixedColor(68, 102, 132);  // 0.8 * soil + 0.2 * straw
constexpr float kMixedDepthMm = 0.8f * kSoilDepthMm + 0.2f * kStrawDepthMm;
const cv::Point kRingPixel(25, 19);
const cv::Point kCornerRingPixel(30, 30);

class MixedStrawEdge : public ::testing::Test {
 protected:
  MixedStrawEdge() {
    scene_.paint(kMixedRing, kMixedColor, kMixedDepthMm);
    scene_.paint(kStrawPatch, kStraw, kStrawDepthMm);
  }
  Scene scene_;
};

TEST_F(MixedStrawEdge, WithoutDilationTheMixedDepthCountsAsSoil) {
  const Output out = segment(scene_, {{"dilation_px", 0}});
  EXPECT_EQ(out.mask.at<std::uint8_t>(kRingPixel), ResidueMask::kSoil);
  EXPECT_EQ(out.soil_depth_mm.at<float>(kRingPixel), kMixedDepthMm);
  EXPECT_EQ(out.soil_depth_mm.at<float>(kCornerRingPixel), kMixedDepthMm);
  EXPECT_EQ(count_finite(out.soil_depth_mm), kSize.area() - kStrawPatch.area());
}

TEST_F(MixedStrawEdge, OnePixelOfDilationExcludesTheMixedRingAndNoMore) {
  const Output out = segment(scene_, {{"dilation_px", 1}});
  EXPECT_EQ(out.mask.at<std::uint8_t>(kRingPixel), ResidueMask::kResidue);
  EXPECT_TRUE(std::isnan(out.soil_depth_mm.at<float>(kRingPixel)));
  EXPECT_TRUE(std::isnan(out.soil_depth_mm.at<float>(kCornerRingPixel)));  // square kernel
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), 12 * 12);
  EXPECT_EQ(count_finite(out.soil_depth_mm), kSize.area() - 12 * 12);
  EXPECT_EQ(out.soil_depth_mm.at<float>(18, 25), kSoilDepthMm);
}

TEST_F(MixedStrawEdge, DilationGrowsByItsRadius) {
  const Output out = segment(scene_, {{"dilation_px", 2}});
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), 14 * 14);
  EXPECT_EQ(count_finite(out.soil_depth_mm), kSize.area() - 14 * 14);
}

TEST(ColorThreshold, UnknownWhereColourIsUntrustedOrDepthMissing) {
  Scene scene;
  scene.color->status.at<std::uint8_t>(5, 5) = RegisteredColor::kOutsideColor;
  scene.color->bgr.at<cv::Vec3b>(5, 5) = cv::Vec3b(0, 0, 0);
  // An occluded pixel whose (wrong) colour happens to be straw's must not grow.
  scene.color->status.at<std::uint8_t>(10, 40) = RegisteredColor::kOccluded;
  scene.color->bgr.at<cv::Vec3b>(10, 40) = kStraw;
  scene.depth->mm.at<float>(30, 10) = kNaN;
  // Straw without depth: unknown itself, but its neighbours are still straw edges.
  scene.color->bgr.at<cv::Vec3b>(30, 40) = kStraw;
  scene.depth->mm.at<float>(30, 40) = kNaN;

  const Output out = segment(scene, {{"dilation_px", 1}});

  for (const cv::Point unknown :
       {cv::Point(5, 5), cv::Point(40, 10), cv::Point(10, 30), cv::Point(40, 30)}) {
    EXPECT_EQ(out.mask.at<std::uint8_t>(unknown), ResidueMask::kUnknown) << unknown;
    EXPECT_TRUE(std::isnan(out.soil_depth_mm.at<float>(unknown))) << unknown;
  }
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kUnknown), 4);
  EXPECT_EQ(out.mask.at<std::uint8_t>(10, 41), ResidueMask::kSoil);
  EXPECT_EQ(out.mask.at<std::uint8_t>(30, 41), ResidueMask::kResidue);
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), 8);
  EXPECT_EQ(count_finite(out.soil_depth_mm), kSize.area() - 4 - 8);
}

// Single residue-coloured pixels on soil (colour noise, demosaicing) and a straw 3 px
// wide: with speckle_px 1 the specks go and the straw stays; with 0 each speck is dilated
// into a (2*2+1)^2 = 25-pixel hole in the soil.
TEST(ColorThreshold, SpeckleRemovalKeepsStrawAndDropsSpecks) {
  Scene scene;
  scene.paint(cv::Rect(10, 5, 3, 30), kStraw, kStrawDepthMm);
  for (const cv::Point speck : {cv::Point(30, 10), cv::Point(40, 30), cv::Point(55, 20)}) {
    scene.paint(cv::Rect(speck, cv::Size(1, 1)), kStraw, kSoilDepthMm);
  }
  const Output kept = segment(scene, {{"speckle_px", 0}});
  const Output cleaned = segment(scene, {{"speckle_px", 1}});
  const int straw = (3 + 4) * (30 + 4);  // the straw dilated by 2 px on each side
  EXPECT_EQ(count_equal(cleaned.mask, ResidueMask::kResidue), straw);
  EXPECT_EQ(count_equal(kept.mask, ResidueMask::kResidue), straw + 3 * 25);
  EXPECT_EQ(count_finite(cleaned.soil_depth_mm), kSize.area() - straw);
}

TEST(ColorThreshold, PixelsDarkerThanMinValueAreUnknown) {
  Scene scene;
  scene.paint(cv::Rect(15, 15, 1, 1), cv::Vec3b(20, 20, 29), kSoilDepthMm);
  EXPECT_EQ(segment(scene, {{"min_value", 30}}).mask.at<std::uint8_t>(15, 15),
            ResidueMask::kUnknown);
  EXPECT_EQ(segment(scene, {{"min_value", 29}}).mask.at<std::uint8_t>(15, 15), ResidueMask::kSoil);
}

TEST(ColorThreshold, ParameterErrorsNameTheParameter) {
  EXPECT_EQ(construction_error({{"residue_lower", {1, 2}}}),
            "parameter 'residue_lower': expected null or an array of 3 integers in [0, 255] "
            "(the colour space's 8-bit channels), got [1,2]");
  EXPECT_EQ(construction_error({{"residue_upper", {0, 0, 256}}}),
            "parameter 'residue_upper': expected null or an array of 3 integers in [0, 255] "
            "(the colour space's 8-bit channels), got [0,0,256]");
  EXPECT_EQ(construction_error({{"residue_lower", {50, 40, 100}}}),
            "parameters 'residue_lower' and 'residue_upper': channel H lower bound 50 > upper "
            "bound 40 (expected lower <= upper)");
  EXPECT_EQ(construction_error({{"color_space", "lab"}, {"residue_upper", {255, 100, 255}}}),
            "parameters 'residue_lower' and 'residue_upper': channel a lower bound 110 > upper "
            "bound 100 (expected lower <= upper)");
}

TEST(ColorThreshold, ColourNotOnTheDepthGridIsAnError) {
  Scene scene;
  scene.depth->mm = cv::Mat(kSize / 2, CV_32FC1, cv::Scalar(kSoilDepthMm));
  TransformHarness stage(describe_color_threshold());
  try {
    stage.run({scene.color, scene.depth});
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "input 'color': bgr 64x48 and status 64x48 do not match the 32x24 depth image "
                 "(expected colour registered onto the depth grid)");
  }
}

// The stage computes its mask from a colour table and packed bit masks; the paper's steps
// done one after another with OpenCV's own operations must give the same outputs, pixel
// for pixel, on noisy frames of straw, soil and random colours with untrusted colours and
// missing depth, for every colour space and for dilation, speck removal and min_value.
struct Steps {
  std::string space;
  int conversion;  // -1: none
  std::vector<int> lower;
  std::vector<int> upper;
  int dilation_px;
  int speckle_px;
  int min_value;
};

Output segment_step_by_step(const Scene& scene, const Steps& steps) {
  const auto square = [](int radius) {
    return cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1});
  };
  const cv::Mat& bgr = scene.color->bgr;
  cv::Mat untrusted = scene.color->status != RegisteredColor::kValid;
  if (steps.min_value > 0) {
    cv::Mat dark;
    cv::inRange(bgr, cv::Scalar::all(0), cv::Scalar::all(steps.min_value - 1), dark);
    untrusted |= dark;
  }
  cv::Mat converted;  // not sharing bgr's pixels: cvtColor would write into them
  if (steps.conversion >= 0) {
    cv::cvtColor(bgr, converted, steps.conversion);
  } else {
    converted = bgr;
  }
  cv::Mat residue;
  cv::inRange(converted, cv::Scalar(steps.lower[0], steps.lower[1], steps.lower[2]),
              cv::Scalar(steps.upper[0], steps.upper[1], steps.upper[2]), residue);
  residue &= ~untrusted;
  if (steps.speckle_px > 0) {
    cv::morphologyEx(residue, residue, cv::MORPH_OPEN, square(steps.speckle_px));
  }
  if (steps.dilation_px > 0) cv::dilate(residue, residue, square(steps.dilation_px));
  const cv::Mat& depth = scene.depth->mm;
  cv::Mat has_depth;
  cv::compare(depth, depth, has_depth, cv::CMP_EQ);  // false only for NaN
  residue.setTo(ResidueMask::kUnknown, untrusted | ~has_depth);
  cv::Mat soil(depth.size(), CV_32FC1, cv::Scalar(kNaN));
  depth.copyTo(soil, residue == ResidueMask::kSoil);
  return {residue, soil};
}

// Straw and soil in blocks with colour noise, 2 % of the pixels any colour at all,
// 5 % untrusted, 5 % without depth; 131 px wide, so rows end inside a word.
Scene noisy_frame() {
  const cv::Size size(131, 97);
  Scene scene;
  scene.color->bgr.create(size, CV_8UC3);
  scene.color->status.create(size, CV_8UC1);
  scene.depth->mm.create(size, CV_32FC1);
  const cv::Vec3b reddish_soil(60, 85, 140);  // hue 9: its noise stays clear of straw's 18
  cv::RNG random(3);
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const bool straw = ((u / 20) + (v / 16)) % 3 == 0;
      const bool any_colour = random.uniform(0.0, 1.0) < 0.02;
      cv::Vec3b& bgr = scene.color->bgr.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) {
        const double base = any_colour ? random.uniform(0.0, 256.0)
                            : straw    ? kStraw[c]
                                       : reddish_soil[c];
        bgr[c] = cv::saturate_cast<std::uint8_t>(base + random.gaussian(6));
      }
      scene.color->status.at<std::uint8_t>(v, u) =
          random.uniform(0.0, 1.0) < 0.05 ? RegisteredColor::kOccluded : RegisteredColor::kValid;
      scene.depth->mm.at<float>(v, u) =
          random.uniform(0.0, 1.0) < 0.05 ? kNaN : static_cast<float>(500.0 + random.gaussian(3));
    }
  }
  return scene;
}

class StepByStep : public ::testing::TestWithParam<Steps> {};

TEST_P(StepByStep, TheStageGivesTheSameMaskAndSoilDepth) {
  const Steps& steps = GetParam();
  const Scene scene = noisy_frame();
  const Output expected = segment_step_by_step(scene, steps);
  const Output out = segment(scene, {{"color_space", steps.space},
                                     {"residue_lower", steps.lower},
                                     {"residue_upper", steps.upper},
                                     {"dilation_px", steps.dilation_px},
                                     {"speckle_px", steps.speckle_px},
                                     {"min_value", steps.min_value}});
  EXPECT_EQ(cv::countNonZero(out.mask != expected.mask), 0);
  EXPECT_EQ(count_finite(out.soil_depth_mm), count_finite(expected.soil_depth_mm));
  cv::Mat same;
  cv::compare(out.soil_depth_mm, expected.soil_depth_mm, same, cv::CMP_EQ);  // NaN: unequal
  EXPECT_EQ(cv::countNonZero(same), count_finite(expected.soil_depth_mm));
  // Each class is present, so the comparison says something about each.
  for (const std::uint8_t value :
       {ResidueMask::kSoil, ResidueMask::kResidue, ResidueMask::kUnknown}) {
    EXPECT_GT(count_equal(expected.mask, value), 200) << int(value);
  }
}

INSTANTIATE_TEST_SUITE_P(
    ColorThreshold, StepByStep,
    ::testing::Values(Steps{"hsv", cv::COLOR_BGR2HSV, {18, 40, 50}, {40, 255, 255}, 2, 0, 0},
                      Steps{"hsv", cv::COLOR_BGR2HSV, {18, 40, 50}, {40, 255, 255}, 2, 1, 0},
                      Steps{"hsv", cv::COLOR_BGR2HSV, {18, 40, 50}, {40, 255, 255}, 0, 0, 0},
                      Steps{"hsv", cv::COLOR_BGR2HSV, {15, 30, 40}, {45, 255, 255}, 3, 2, 60},
                      Steps{"lab", cv::COLOR_BGR2Lab, {50, 110, 140}, {255, 132, 255}, 1, 1, 0},
                      Steps{"bgr", -1, {0, 140, 160}, {255, 255, 255}, 5, 0, 30}),
    [](const auto& info) {
      const Steps& steps = info.param;
      return steps.space + "_dilation" + std::to_string(steps.dilation_px) + "_speckle" +
             std::to_string(steps.speckle_px) + "_min" + std::to_string(steps.min_value);
    });

TEST(ColorThreshold, ReusesOutputBuffersNoOneHolds) {
  Scene scene;
  TransformHarness stage(describe_color_threshold());
  const std::uint8_t* first_mask = nullptr;
  {
    const auto out = stage.run({scene.color, scene.depth}, 0);
    first_mask = out[0].get<ResidueMask>().values.data;
  }
  const auto kept = stage.run({scene.color, scene.depth}, 1);
  EXPECT_EQ(kept[0].get<ResidueMask>().values.data, first_mask);

  // Frame 1's mask is still held: frame 2 must not write into it.
  scene.paint(cv::Rect(0, 0, kSize.width, kSize.height), kStraw, kStrawDepthMm);
  const auto next = stage.run({scene.color, scene.depth}, 2);
  EXPECT_NE(next[0].get<ResidueMask>().values.data, first_mask);
  EXPECT_EQ(count_equal(kept[0].get<ResidueMask>().values, ResidueMask::kSoil), kSize.area());
  EXPECT_EQ(count_equal(next[0].get<ResidueMask>().values, ResidueMask::kResidue), kSize.area());
}

// The stage is declared kParallel: frames from several threads at once must each get
// their own, correct mask (pooled outputs, per-thread working images).
TEST(ColorThreshold, ConcurrentFramesGetTheirOwnResults) {
  Scene soil_only;
  Scene half_straw;
  half_straw.paint(cv::Rect(0, 0, kSize.width / 2, kSize.height), kStraw, kStrawDepthMm);
  TransformHarness stage(describe_color_threshold());
  const cv::Mat expected_soil_only =
      stage.run({soil_only.color, soil_only.depth})[0].get<ResidueMask>().values.clone();
  const cv::Mat expected_half_straw =
      stage.run({half_straw.color, half_straw.depth})[0].get<ResidueMask>().values.clone();
  ASSERT_GT(cv::countNonZero(expected_soil_only != expected_half_straw), 0);

  std::atomic<int> wrong{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (int i = 0; i < 50; ++i) {
        const bool straw = (i + t) % 2 == 0;
        const Scene& scene = straw ? half_straw : soil_only;
        const auto out = stage.run({scene.color, scene.depth}, static_cast<std::uint64_t>(i));
        const cv::Mat& expected = straw ? expected_half_straw : expected_soil_only;
        if (cv::countNonZero(out[0].get<ResidueMask>().values != expected) != 0) ++wrong;
      }
    });
  }
  for (auto& thread : threads) thread.join();
  EXPECT_EQ(wrong, 0);
}

}  // namespace
}  // namespace tilth::segmentation
