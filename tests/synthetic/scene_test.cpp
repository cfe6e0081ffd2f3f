// The scene simulator against geometry computed independently: flat soil gives eq. 1's
// inverse exactly before noise; the truth follows the soil layers of the moving
// platform; frames are deterministic per seed; residue shows in the truth mask; cracks lie
// below the soil; a scene's own fields change a preset, and bad ones are refused by name.
#include <algorithm>
#include <chrono>
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "framework/stage_registry.h"
#include "source_tree.h"
#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/stage_params.h"

namespace tilth {
namespace {

const std::string kCalibration = testing::paper_rig_path().string();

struct SceneFrame {
  RawTofFrame raw;
  ColorImage color;
  GroundTruth truth;
  FrameInfo info;
};

class SceneTest : public ::testing::Test {
 protected:
  SceneTest() { registry_.load(TILTH_SYNTHETIC_PLUGIN); }

  // Makes the stage with its defaults and these parameters, and produces `count` frames.
  std::vector<SceneFrame> frames(nlohmann::json params, int count) {
    params["calibration"] = kCalibration;
    StageContext context{"scene",
                         stage_params(registry_.find("synthetic.scene")->descriptor, params),
                         Logger("scene"),
                         {}};
    StageInstance instance = registry_.create("synthetic.scene", context);
    auto* source = dynamic_cast<Source*>(instance.stage.get());
    std::vector<SceneFrame> result;
    for (int i = 0; i < count; ++i) {
      std::vector<Packet> outputs(3);
      Frame frame(FrameInfo{}, {}, outputs);
      if (!source->produce(frame)) break;
      result.push_back({outputs[0].get<RawTofFrame>(), outputs[1].get<ColorImage>(),
                        outputs[2].get<GroundTruth>(), frame.info()});
    }
    return result;
  }

  StageRegistry registry_;
};

TEST_F(SceneTest, FlatSoilIsEquationOneInvertedExactly) {
  const auto produced = frames({{"preset", "flat"}, {"noise_mm", 0.0}, {"dropout", 0.0}}, 1);
  ASSERT_EQ(produced.size(), 1u);
  const RigCalibration rig = load_calibration(kCalibration);
  const cv::Mat& gray = produced[0].raw.gray;
  ASSERT_EQ(gray.size(), cv::Size(640, 480));
  // Eq. 1 solved for g: the optical-centre depth Z = 518 + 23.97 mm along the pixel's ray
  // is the range Z * sqrt(x'^2 + y'^2 + 1), and g = round(range / mu).
  const long double z = 518.0L + rig.depth.z_offset_mm;
  int checked = 0;
  for (int v = 0; v < gray.rows; ++v) {
    for (int u = 0; u < gray.cols; ++u) {
      const long double x = (u - rig.depth.cx) / rig.depth.fx;
      const long double y = (v - rig.depth.cy) / rig.depth.fy;
      const long double range = z * std::sqrt(x * x + y * y + 1.0L);
      const long double expected = std::round(range / rig.depth.gray_to_mm);
      // The simulator keeps ray directions and ranges in float32 (relative precision 6e-8:
      // 4e-5 mm at 600 mm, 0.002 gray steps): skip pixels whose exact value lies within
      // 0.005 gray steps of a rounding boundary, where float rounding may go either way.
      const long double scaled = range / rig.depth.gray_to_mm;
      if (std::abs(scaled - std::floor(scaled) - 0.5L) < 5e-3L) continue;
      ASSERT_EQ(gray.at<std::uint16_t>(v, u), static_cast<std::uint16_t>(expected))
          << "pixel (" << u << ", " << v << ")";
      ++checked;
    }
  }
  EXPECT_GT(checked, 640 * 480 * 98 / 100);
  EXPECT_EQ(cv::countNonZero(produced[0].truth.residue_mask), 0);
  EXPECT_DOUBLE_EQ(*produced[0].truth.distance_mm, 518.0);
}

TEST_F(SceneTest, ResidueAppearsInTheTruthMaskAndInColour) {
  const auto produced = frames({{"preset", "case_d"}}, 1);
  const cv::Mat& mask = produced[0].truth.residue_mask;
  const double residue = cv::countNonZero(mask == ResidueMask::kResidue) / double(mask.total());
  const double mixed = cv::countNonZero(mask == ResidueMask::kUnknown) / double(mask.total());
  // 300 straws of 3-6 mm x 40-250 mm over ~0.5 m^2 and 60 stalks: tens of percent cover.
  EXPECT_GT(residue, 0.15);
  EXPECT_LT(residue, 0.75);
  // Straw edges produce mixed pixels.
  EXPECT_GT(mixed, 0.01);
  EXPECT_EQ(produced[0].color.pixels.size(), cv::Size(1280, 1024));
  EXPECT_EQ(produced[0].color.pixels.type(), CV_8UC3);
}

TEST_F(SceneTest, SameSeedSameFramesOtherSeedOtherFrames) {
  const auto first = frames({{"preset", "case_b"}, {"seed", 7}}, 2);
  const auto again = frames({{"preset", "case_b"}, {"seed", 7}}, 2);
  const auto other = frames({{"preset", "case_b"}, {"seed", 8}}, 1);
  EXPECT_EQ(cv::norm(first[1].raw.gray, again[1].raw.gray, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(first[1].color.pixels, again[1].color.pixels, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(first[0].raw.gray, other[0].raw.gray, cv::NORM_L1), 0.0);
  // Noise differs from frame to frame of one run.
  EXPECT_GT(cv::norm(first[0].raw.gray, first[1].raw.gray, cv::NORM_L1), 0.0);
  // Timestamps: 30 frames/s, the colour camera 0.4 ms after the ToF camera.
  EXPECT_EQ(first[1].raw.device_timestamp_ns - first[0].raw.device_timestamp_ns, 33'333'333);
  EXPECT_EQ(first[1].color.device_timestamp_ns - first[1].raw.device_timestamp_ns, 400'000);
  EXPECT_EQ(first[1].info.frame_id, 1u);
}

TEST_F(SceneTest, LayeredPlatformTruthFollowsTheLayers) {
  // 400 mm/s at 30 frames/s: 13.33 mm per frame; layers change every 800 mm (60 frames).
  const double expected[] = {455.0, 435.0, 415.0, 395.0, 375.0};
  for (int layer = 0; layer < 5; ++layer) {
    const auto produced = frames({{"preset", "layered"}, {"first_frame", layer * 60 + 30}}, 1);
    ASSERT_EQ(produced.size(), 1u);
    EXPECT_EQ(produced[0].info.frame_id, static_cast<std::uint64_t>(layer * 60 + 30));
    EXPECT_DOUBLE_EQ(*produced[0].truth.distance_mm, expected[layer]) << layer;
  }
}

// A frame's host time is when it was made (here paced at 10 frames/s), or with host_time
// "recorded" the simulated capture time: the device clock (30 frames/s) from the first
// frame's host time, as the cameras would have stamped it however slowly frames render.
TEST_F(SceneTest, HostTimesAreWhenMadeOrTheSimulatedCaptureTimes) {
  const auto now_ns = [] {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  };
  const std::int64_t before_ns = now_ns();
  const auto simulated = frames({{"preset", "case_a"}, {"fps", 10}, {"host_time", "recorded"}}, 3);
  const std::int64_t after_ns = now_ns();
  ASSERT_EQ(simulated.size(), 3u);
  EXPECT_GE(simulated[0].info.host_timestamp_ns, before_ns);
  EXPECT_LE(simulated[0].info.host_timestamp_ns, after_ns);
  EXPECT_EQ(simulated[1].info.host_timestamp_ns - simulated[0].info.host_timestamp_ns, 33'333'333);
  EXPECT_EQ(simulated[2].info.host_timestamp_ns - simulated[0].info.host_timestamp_ns, 66'666'666);

  const auto made = frames({{"preset", "case_a"}, {"fps", 10}}, 2);
  ASSERT_EQ(made.size(), 2u);
  // 100 ms apart, give or take the difference of the two frames' noising.
  EXPECT_GT(made[1].info.host_timestamp_ns - made[0].info.host_timestamp_ns, 50'000'000);
}

// Dry clay (preset cracked): cracks 10-20 mm deep below the clods' surface, which the truth
// keeps to. Against flat soil, without noise: soil pixels seen in the cracks lie farther
// than the micro-relief reaches (1.5 mm, under 4 mm at its peaks), none farther than the
// deepest crack plus the relief, along a ray at most 10 % longer than the depth off the
// optical axis (the paper rig's corners).
TEST_F(SceneTest, CracksLieBelowTheClodsNoDeeperThanThePresetSays) {
  nlohmann::json params = {{"noise_mm", 0.0}, {"dropout", 0.0}, {"preset", "cracked"}};
  const auto cracked = frames(params, 1);
  params["preset"] = "flat";
  const auto flat = frames(params, 1);
  ASSERT_EQ(cracked.size(), 1u);
  ASSERT_EQ(flat.size(), 1u);
  const double mm_per_gray = load_calibration(kCalibration).depth.gray_to_mm;
  const cv::Mat& truth = cracked[0].truth.residue_mask;
  int soil = 0;
  int in_cracks = 0;
  double deepest_mm = 0.0;
  for (int v = 0; v < truth.rows; ++v) {
    for (int u = 0; u < truth.cols; ++u) {
      if (truth.at<std::uint8_t>(v, u) != ResidueMask::kSoil) continue;
      const double beyond_mm =
          (cracked[0].raw.gray.at<std::uint16_t>(v, u) - flat[0].raw.gray.at<std::uint16_t>(v, u)) *
          mm_per_gray;
      ++soil;
      in_cracks += beyond_mm > 5.0;
      deepest_mm = std::max(deepest_mm, beyond_mm);
    }
  }
  EXPECT_GT(in_cracks, soil / 100) << in_cracks << " of " << soil;
  EXPECT_LT(in_cracks, soil / 5) << in_cracks << " of " << soil;
  EXPECT_GT(deepest_mm, 15.0);
  EXPECT_LT(deepest_mm, 1.1 * 20.0 + 4.0);
  EXPECT_DOUBLE_EQ(*cracked[0].truth.distance_mm, 518.0);
}

TEST_F(SceneTest, BayerMosaicKeepsOneChannelPerPixel) {
  const auto bgr = frames({{"preset", "case_a"}, {"color_noise", 0.0}}, 1);
  const auto rggb =
      frames({{"preset", "case_a"}, {"color_noise", 0.0}, {"color_format", "bayer_rggb8"}}, 1);
  ASSERT_EQ(rggb[0].color.format, PixelFormat::kBayerRggb8);
  const cv::Mat& mosaic = rggb[0].color.pixels;
  const cv::Mat& colour = bgr[0].color.pixels;
  // R at (even, even), G at (even, odd) and (odd, even), B at (odd, odd).
  EXPECT_EQ(mosaic.at<std::uint8_t>(100, 200), colour.at<cv::Vec3b>(100, 200)[2]);
  EXPECT_EQ(mosaic.at<std::uint8_t>(100, 201), colour.at<cv::Vec3b>(100, 201)[1]);
  EXPECT_EQ(mosaic.at<std::uint8_t>(101, 200), colour.at<cv::Vec3b>(101, 200)[1]);
  EXPECT_EQ(mosaic.at<std::uint8_t>(101, 201), colour.at<cv::Vec3b>(101, 201)[0]);
}

// The `scene` parameter changes the preset's fields: case D without its straws and stubble
// is bare soil (no residue pixel in the truth), 600 mm away, of the colour given.
TEST_F(SceneTest, SceneFieldsChangeThePreset) {
  const auto changed = frames({{"preset", "case_d"},
                               {"color_noise", 0.0},
                               {"scene",
                                {{"straws", 0},
                                 {"stubble", 0},
                                 {"ground_distance_mm", 600.0},
                                 {"soil_bgr", {0.1, 0.2, 0.6}}}}},
                              1);
  ASSERT_EQ(changed.size(), 1u);
  EXPECT_EQ(cv::countNonZero(changed[0].truth.residue_mask != ResidueMask::kSoil), 0);
  EXPECT_DOUBLE_EQ(*changed[0].truth.distance_mm, 600.0);
  // Reflectance ratio red to blue 6 (the preset's soil: 2), under a white sun and a grey sky.
  const cv::Scalar mean = cv::mean(changed[0].color.pixels);
  EXPECT_NEAR(mean[2] / mean[0], 6.0, 0.3);
  EXPECT_NEAR(mean[1] / mean[0], 2.0, 0.1);
}

TEST_F(SceneTest, BadSceneFieldsAreRefusedByName) {
  const auto refused = [&](nlohmann::json scene) {
    try {
      frames({{"preset", "case_a"}, {"scene", std::move(scene)}}, 1);
    } catch (const std::exception& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  using ::testing::HasSubstr;
  EXPECT_THAT(refused({{"strawz", 10}}),
              HasSubstr("no preset field 'strawz'; the fields are ground_distance_mm, stubble"));
  EXPECT_THAT(refused({{"straws", -1}}),
              HasSubstr("field 'straws': expected an integer from 0 to 50000, got -1"));
  EXPECT_THAT(refused({{"straws", 2.5}}), HasSubstr("field 'straws': expected an integer"));
  EXPECT_THAT(refused({{"soil_bgr", {0.1, 0.2}}}),
              HasSubstr("field 'soil_bgr': expected [3 numbers] each from 0 to 1, got [0.1,0.2]"));
  EXPECT_THAT(refused({{"straw_length_mm", {200, 40}}}),
              HasSubstr("the first not above the second"));
  EXPECT_THAT(refused({{"shadows", 1}}), HasSubstr("field 'shadows': expected true or false"));
  EXPECT_THAT(refused({{"stubble_height_mm", 10}, {"stubble_height_spread_mm", 20}}),
              HasSubstr("stalks would grow below the soil"));
  EXPECT_THAT(refused({{"layers_mm", {0, 5}}}), HasSubstr("need a track"));
  EXPECT_THAT(refused(5), HasSubstr("expected an object of preset fields, got 5"));
}

}  // namespace
}  // namespace tilth
