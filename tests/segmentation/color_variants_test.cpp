// segmentation.color_index and segmentation.lab_clusters on painted frames: straw against
// soil in every index, the reference colours of docs/segmentation.md, frames of one
// material (bare soil, straw in sun and shadow) that an automatic split must not cut in
// two, shadows, and determinism.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "painted_frame.h"
#include "tilth/log.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;

const cv::Size kSize(64, 48);
constexpr float kSoilMm = 500.0f;
const cv::Vec3b kStraw(120, 190, 220);
const cv::Vec3b kShadowedStraw(60, 95, 110);
const cv::Vec3b kSoil(55, 80, 110);
const cv::Vec3b kShadowedSoil(27, 40, 55);
const cv::Rect kLeftHalf(0, 0, kSize.width / 2, kSize.height);
const cv::Rect kRightHalf(kSize.width / 2, 0, kSize.width / 2, kSize.height);

// Sensor noise of 3 DN (the simulator's is 2), fixed seed.
void add_noise(PaintedFrame& frame, double sigma = 3.0) {
  cv::Mat noise(kSize, CV_16SC3);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  cv::Mat noisy;
  frame.color->bgr.convertTo(noisy, CV_16SC3);
  noisy += noise;
  noisy.convertTo(frame.color->bgr, CV_8UC3);
}

// Log lines of the stage under test, to see what it says about a frame.
class CapturedLog {
 public:
  CapturedLog() {
    previous_ = set_log_handler([this](LogLevel, std::string_view, std::string_view message) {
      text_ += std::string(message) + "\n";
    });
  }
  ~CapturedLog() { set_log_handler(previous_); }
  const std::string& text() const { return text_; }

 private:
  LogHandler previous_;
  std::string text_;
};

struct Variant {
  std::string name;
  StageDescriptor (*describe)();
  json params;
};

void PrintTo(const Variant& variant, std::ostream* out) { *out << variant.name; }

std::vector<Variant> automatic_colour_variants() {
  return {{"exg", describe_color_index, {{"index", "exg"}}},
          {"exr", describe_color_index, {{"index", "exr"}}},
          {"exgr", describe_color_index, {{"index", "exgr"}}},
          {"hue", describe_color_index, {{"index", "hue"}}},
          {"lab_clusters", describe_lab_clusters, json::object()}};
}

json exact(json params) {
  params["dilation_px"] = 0;
  params["speckle_px"] = 0;
  params["smoothing_px"] = 0;
  return params;
}

class EachColourVariant : public ::testing::TestWithParam<Variant> {};

TEST_P(EachColourVariant, SeparatesStrawFromSoilExactly) {
  PaintedFrame frame(kSize, kSoil, kSoilMm);
  frame.paint(kLeftHalf, kStraw);
  const Segmented out = segment(GetParam().describe(), exact(GetParam().params), frame);
  EXPECT_EQ(count_equal(out.mask(kLeftHalf), ResidueMask::kResidue), kLeftHalf.area());
  EXPECT_EQ(count_equal(out.mask(kRightHalf), ResidueMask::kSoil), kRightHalf.area());
  EXPECT_EQ(cv::countNonZero(out.soil_depth_mm(kRightHalf) != kSoilMm), 0);
}

// Straw and soil each half in sun, half in shadow: the split must follow the material,
// not the light.
TEST_P(EachColourVariant, SplitsByMaterialNotByLight) {
  PaintedFrame frame(kSize, kSoil, kSoilMm);
  frame.paint({0, 0, 32, 24}, kStraw);
  frame.paint({0, 24, 32, 24}, kShadowedStraw);
  frame.paint({32, 24, 32, 24}, kShadowedSoil);
  add_noise(frame);
  json params = GetParam().params;
  params["dilation_px"] = 0;
  const Segmented out = segment(GetParam().describe(), params, frame);
  // The 3x3 mean mixes the two materials along the boundary column pair only.
  const cv::Rect straw(0, 0, 31, 48);
  const cv::Rect soil(33, 0, 31, 48);
  EXPECT_EQ(count_equal(out.mask(straw), ResidueMask::kResidue), straw.area());
  EXPECT_EQ(count_equal(out.mask(soil), ResidueMask::kSoil), soil.area());
}

// Bare soil, lit and shaded, with noise: Otsu's split of it is noise, and the variants
// must see one material and keep it all soil.
TEST_P(EachColourVariant, BareSoilIsAllSoil) {
  PaintedFrame frame(kSize, kSoil, kSoilMm);
  frame.paint(kLeftHalf, kShadowedSoil);
  add_noise(frame);
  CapturedLog log;
  const Segmented out = segment(GetParam().describe(), GetParam().params, frame);
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kSoil), kSize.area());
  EXPECT_NE(log.text().find("one material only"), std::string::npos) << log.text();
}

// A frame covered by straw, in sun and in the shadow of other straw: all residue.
TEST_P(EachColourVariant, CoveredFrameIsAllResidue) {
  PaintedFrame frame(kSize, kStraw, kSoilMm);
  frame.paint(kLeftHalf, kShadowedStraw);
  add_noise(frame);
  CapturedLog log;
  const Segmented out = segment(GetParam().describe(), GetParam().params, frame);
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), kSize.area());
  EXPECT_NE(log.text().find("one material only"), std::string::npos) << log.text();
}

TEST_P(EachColourVariant, SameFrameSameMask) {
  PaintedFrame frame(kSize, kSoil, kSoilMm);
  frame.paint({5, 5, 20, 30}, kStraw);
  frame.paint({40, 10, 6, 30}, kShadowedStraw);
  add_noise(frame, 6.0);
  const Segmented first = segment(GetParam().describe(), GetParam().params, frame);
  const Segmented again = segment(GetParam().describe(), GetParam().params, frame);
  EXPECT_EQ(cv::countNonZero(first.mask != again.mask), 0);
}

INSTANTIATE_TEST_SUITE_P(Segmentation, EachColourVariant,
                         ::testing::ValuesIn(automatic_colour_variants()),
                         [](const auto& info) { return info.param.name; });

// The reference colours of docs/segmentation.md side by side, five columns each: what
// the excess-green index and the clusters call them. Wet straw is soil to both; the dry
// light soil, whose lightness-normalised chroma is as low as pale straw's, falls on the
// straw side of the clusters' boundary.
struct ReferenceColour {
  const char* name;
  cv::Vec3b bgr;
  bool residue_by_exg;
  bool residue_by_clusters;
};

const std::vector<ReferenceColour> kReferenceColours = {
    {"straw", {120, 190, 220}, true, true},
    {"pale straw", {170, 215, 230}, true, true},
    {"golden straw", {60, 160, 200}, true, true},
    {"grey old straw", {130, 160, 170}, true, true},
    {"shadowed straw", {60, 95, 110}, true, true},
    {"straw in a straw's shadow", {44, 80, 94}, true, true},
    {"straw's shaded side in shadow", {26, 48, 56}, true, true},
    {"wet straw", {34, 53, 72}, false, false},
    {"brown soil", {55, 80, 110}, false, false},
    {"dark moist soil", {45, 55, 70}, false, false},
    {"dry light soil", {100, 125, 150}, false, true},
    {"reddish soil", {60, 85, 140}, false, false},
};

TEST(ReferenceColours, ClassifiedAsDocumented) {
  PaintedFrame frame(kSize, kSoil, kSoilMm);
  for (std::size_t i = 0; i < kReferenceColours.size(); ++i) {
    frame.paint({static_cast<int>(i) * 5, 0, 5, kSize.height}, kReferenceColours[i].bgr);
  }
  const Segmented by_exg = segment(describe_color_index(), exact({{"index", "exg"}}), frame);
  const Segmented by_clusters = segment(describe_lab_clusters(), exact(json::object()), frame);
  for (std::size_t i = 0; i < kReferenceColours.size(); ++i) {
    const int column = static_cast<int>(i) * 5 + 2;
    EXPECT_EQ(by_exg.mask.at<std::uint8_t>(0, column) == ResidueMask::kResidue,
              kReferenceColours[i].residue_by_exg)
        << kReferenceColours[i].name;
    EXPECT_EQ(by_clusters.mask.at<std::uint8_t>(0, column) == ResidueMask::kResidue,
              kReferenceColours[i].residue_by_clusters)
        << kReferenceColours[i].name;
  }
}

TEST(ColorIndex, UntrustedColourAndMissingDepthAreUnknownAndDoNotGrow) {
  PaintedFrame frame(kSize, kSoil, kSoilMm);
  frame.paint({0, 0, 20, kSize.height}, kStraw);
  frame.color->status.at<std::uint8_t>(10, 40) = RegisteredColor::kOccluded;
  frame.color->bgr.at<cv::Vec3b>(10, 40) = kStraw;  // an occluded pixel's wrong colour
  frame.depth->mm.at<float>(30, 50) = std::numeric_limits<float>::quiet_NaN();
  const Segmented out = segment(
      describe_color_index(), {{"speckle_px", 0}, {"dilation_px", 1}, {"smoothing_px", 0}}, frame);
  EXPECT_EQ(out.mask.at<std::uint8_t>(10, 40), ResidueMask::kUnknown);
  EXPECT_EQ(out.mask.at<std::uint8_t>(10, 41), ResidueMask::kSoil);
  EXPECT_EQ(out.mask.at<std::uint8_t>(30, 50), ResidueMask::kUnknown);
  EXPECT_TRUE(std::isnan(out.soil_depth_mm.at<float>(30, 50)));
  // The straw grows by one pixel.
  EXPECT_EQ(count_equal(out.mask, ResidueMask::kResidue), 21 * kSize.height);
}

}  // namespace
}  // namespace tilth::segmentation
