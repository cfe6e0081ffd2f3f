// The `roi` parameter: what each value means on an image, clipping, and the errors.
#include "roi/region_of_interest.h"

#include <gtest/gtest.h>

#include "tilth/error.h"

namespace tilth {
namespace {

using Whole = RegionOfInterest::Whole;
const cv::Size kImage(640, 480);

TEST(RegionOfInterest, NullIsWhatTheStageSaysANamedRegionIsTheSameEverywhere) {
  EXPECT_EQ(RegionOfInterest(nullptr, Whole::kImage).on(kImage), cv::Rect(0, 0, 640, 480));
  EXPECT_EQ(RegionOfInterest(nullptr, Whole::kMiddleHalf).on(kImage), cv::Rect(160, 120, 320, 240));
  for (const Whole when_null : {Whole::kImage, Whole::kMiddleHalf}) {
    EXPECT_EQ(RegionOfInterest("middle_half", when_null).on(kImage), cv::Rect(160, 120, 320, 240));
    EXPECT_EQ(RegionOfInterest("middle_half", when_null).on({160, 120}), cv::Rect(40, 30, 80, 60));
    EXPECT_EQ(RegionOfInterest("image", when_null).on(kImage), cv::Rect(0, 0, 640, 480));
  }
}

TEST(RegionOfInterest, PixelsAreClippedToTheImageAndTheClippingIsTold) {
  const RegionOfInterest roi({{"x", 600}, {"y", 400}, {"width", 100}, {"height", 200}},
                             Whole::kImage);
  EXPECT_EQ(roi.on(kImage), cv::Rect(600, 400, 40, 80));
  EXPECT_TRUE(roi.clipped_on(kImage));
  EXPECT_FALSE(roi.clipped_on({800, 600}));
  EXPECT_EQ(roi.clipping_note(kImage),
            "roi x 600, y 400, 100x200 reaches outside the 640x480 image; using x 600, y 400, "
            "40x80");
}

TEST(RegionOfInterest, ShapesOtherThanTheFourAreErrorsThatSayWhatIsExpected) {
  const auto error = [](const nlohmann::json& value) -> std::string {
    try {
      RegionOfInterest(value, Whole::kImage).on(kImage);
    } catch (const Error& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error("middle"),
            "parameter 'roi': expected null, \"image\", \"middle_half\" or {\"x\", \"y\", "
            "\"width\", \"height\"} in pixels, got \"middle\"");
  EXPECT_EQ(error({{"x", 0}, {"y", 0}, {"width", 10}}),
            "parameter 'roi': missing field \"height\"");
  EXPECT_EQ(error({{"x", 700}, {"y", 0}, {"width", 10}, {"height", 10}}),
            "parameter 'roi': x 700, y 0, 10x10 lies outside the 640x480 depth image");
}

}  // namespace
}  // namespace tilth
