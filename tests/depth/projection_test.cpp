// depth.projection against eq. 1 of the paper and docs/formats/calibration.md, with the
// expected values computed here in long double from the formulas, never by the stage.
//
// Tolerance kMm = 1e-3 mm unless noted: the stage works in float32, whose spacing at
// 512-1024 mm is 6.1e-5 mm, and rounds about four times per pixel (scale, offset,
// factor, z offset), so its error stays below 1e-3 mm. That is 1/20 of one gray step
// (0.0229 mm) and 1/700 of what 1-based pixel indices would move a corner pixel's depth
// (0.72 mm at 518 mm), so the tests see either.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <span>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "calibration_file.h"
#include "projection.h"
#include "source_tree.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/frame.h"
#include "tilth/log.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/raw_tof_frame.h"

namespace tilth::depth {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kMm = 1e-3;

const fs::path kPaperRig = testing::paper_rig_path();

using testing::CalibrationFile;

std::unique_ptr<Transform> make_projection(const fs::path& calibration,
                                           int saturated_gray = 65535) {
  const StageContext context{
      "projection",
      Params(json{{"calibration", calibration.string()}, {"saturated_gray", saturated_gray}}),
      Logger("projection"),
      {}};
  std::unique_ptr<Stage> stage = describe_projection().create(context);
  auto* transform = dynamic_cast<Transform*>(stage.get());
  if (transform == nullptr) throw std::logic_error("depth.projection is not a transform");
  stage.release();
  return std::unique_ptr<Transform>(transform);
}

std::shared_ptr<const DepthImage> project(Transform& stage, RawTofFrame raw) {
  const Packet input(FrameInfo{}, std::make_shared<const RawTofFrame>(std::move(raw)));
  std::vector<Packet> outputs(1);
  Frame frame(FrameInfo{}, std::span<const Packet>(&input, 1), outputs);
  stage.process(frame);
  return outputs[0].share<DepthImage>();
}

RawTofFrame uniform_frame(std::uint16_t gray, int width = 640, int height = 480) {
  RawTofFrame raw;
  raw.gray = cv::Mat(height, width, CV_16UC1, cv::Scalar(gray));
  return raw;
}

std::string construction_error(const fs::path& calibration) {
  try {
    make_projection(calibration);
  } catch (const Error& error) {
    return error.what();
  }
  return "constructed";
}

// Paper eq. 1, 0-based pixels: z = g mu / sqrt(((u-cx)/f)^2 + ((v-cy)/f)^2 + 1) - z_offset.
long double eq1(long double gray, int u, int v) {
  const long double mu = 0.0229L;
  const long double f = 509.935L;
  const long double x = (u - 313.05L) / f;
  const long double y = (v - 239.60L) / f;
  return gray * mu / std::sqrt(x * x + y * y + 1.0L) - 23.97L;
}

struct Pixel {
  int u;
  int v;
  std::uint16_t gray;
};

TEST(DepthProjection, Eq1AtTheCentreAndTheFourCorners) {
  const auto stage = make_projection(kPaperRig);
  // About 518 mm of soil (the paper's mounting height) and a spread of other values.
  const std::vector<Pixel> pixels = {
      {313, 240, 23666}, {0, 0, 27000}, {639, 0, 30000}, {0, 479, 45000}, {639, 479, 65534}};
  RawTofFrame raw = uniform_frame(20000);
  for (const auto& p : pixels) raw.gray.at<std::uint16_t>(p.v, p.u) = p.gray;
  const auto depth = project(*stage, raw);
  ASSERT_EQ(depth->mm.type(), CV_32FC1);
  ASSERT_EQ(depth->mm.size(), cv::Size(640, 480));
  for (const auto& p : pixels) {
    EXPECT_NEAR(depth->mm.at<float>(p.v, p.u), static_cast<double>(eq1(p.gray, p.u, p.v)), kMm)
        << "pixel (" << p.u << ", " << p.v << ")";
  }
}

TEST(DepthProjection, ZMeasureSubtractsOnlyTheOffsets) {
  json rig = testing::paper_rig_document();
  rig["depth_camera"]["depth_measure"] = "z";
  rig["depth_camera"]["gray_offset_mm"] = 4.5;
  const CalibrationFile file(rig);
  const auto stage = make_projection(file.path());
  const auto depth = project(*stage, uniform_frame(23666));
  const long double expected = 23666 * 0.0229L + 4.5L - 23.97L;
  for (const auto& [u, v] : std::vector<std::pair<int, int>>{{313, 240}, {0, 0}, {639, 479}}) {
    EXPECT_NEAR(depth->mm.at<float>(v, u), static_cast<double>(expected), kMm)
        << "pixel (" << u << ", " << v << ")";
  }
}

TEST(DepthProjection, GrayZeroIsNoDepth) {
  const auto stage = make_projection(kPaperRig);
  RawTofFrame raw = uniform_frame(23666);
  raw.gray.at<std::uint16_t>(0, 0) = 0;
  raw.gray.at<std::uint16_t>(240, 313) = 0;
  raw.gray.at<std::uint16_t>(479, 639) = 0;
  const auto depth = project(*stage, raw);
  EXPECT_TRUE(std::isnan(depth->mm.at<float>(0, 0)));
  EXPECT_TRUE(std::isnan(depth->mm.at<float>(240, 313)));
  EXPECT_TRUE(std::isnan(depth->mm.at<float>(479, 639)));
  EXPECT_NEAR(depth->mm.at<float>(240, 314), static_cast<double>(eq1(23666, 314, 240)), kMm);
  int no_depth = 0;
  for (auto it = depth->mm.begin<float>(); it != depth->mm.end<float>(); ++it) {
    no_depth += std::isnan(*it) ? 1 : 0;
  }
  EXPECT_EQ(no_depth, 3);
}

TEST(DepthProjection, TheCamerasScaleAndOffsetWinOverTheFile) {
  const auto stage = make_projection(kPaperRig);
  RawTofFrame both = uniform_frame(20000);
  both.scale_mm = 0.025;
  both.offset_mm = -3.0;
  const auto depth = project(*stage, both);
  const auto expected = [](long double range, int u, int v) {
    const long double x = (u - 313.05L) / 509.935L;
    const long double y = (v - 239.60L) / 509.935L;
    return static_cast<double>(range / std::sqrt(x * x + y * y + 1.0L) - 23.97L);
  };
  EXPECT_NEAR(depth->mm.at<float>(240, 313), expected(20000 * 0.025L - 3.0L, 313, 240), kMm);
  EXPECT_NEAR(depth->mm.at<float>(0, 639), expected(20000 * 0.025L - 3.0L, 639, 0), kMm);

  RawTofFrame scale_only = uniform_frame(20000);
  scale_only.scale_mm = 0.025;
  json rig = testing::paper_rig_document();
  rig["depth_camera"]["gray_offset_mm"] = 7.0;
  const CalibrationFile file(rig);
  const auto with_file_offset = project(*make_projection(file.path()), scale_only);
  EXPECT_NEAR(with_file_offset->mm.at<float>(479, 0), expected(20000 * 0.025L + 7.0L, 0, 479), kMm);
}

// OpenCV's model, k1 k2 p1 p2 k3, on a normalised point.
cv::Point2d distort(const std::array<long double, 5>& k, long double x, long double y) {
  const long double r2 = x * x + y * y;
  const long double radial = 1 + k[0] * r2 + k[1] * r2 * r2 + k[4] * r2 * r2 * r2;
  return {static_cast<double>(x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x)),
          static_cast<double>(y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y)};
}

TEST(DepthProjection, DistortionIsUndoneBeforeTheFactor) {
  // Strong barrel distortion with tangential terms, invertible over the image.
  const std::array<long double, 5> k = {-0.28L, 0.09L, 0.0012L, -0.0007L, -0.012L};
  const long double f = 509.935L;
  // A known normalised point is distorted forward; the principal point is then chosen so
  // that it lands exactly on an integer pixel, where the stage's factor must be
  // 1 / sqrt(x^2 + y^2 + 1) of the undistorted point.
  struct Case {
    long double x, y;
    int u, v;
  };
  for (const Case c :
       {Case{0.62L, 0.45L, 600, 450}, Case{-0.55L, -0.41L, 25, 20}, Case{0.05L, -0.30L, 330, 95}}) {
    const cv::Point2d distorted = distort(k, c.x, c.y);
    json rig = testing::paper_rig_document();
    rig["depth_camera"]["distortion"] = {k[0], k[1], k[2], k[3], k[4]};
    rig["depth_camera"]["cx"] = static_cast<double>(c.u - f * distorted.x);
    rig["depth_camera"]["cy"] = static_cast<double>(c.v - f * distorted.y);
    const CalibrationFile file(rig);
    const auto depth = project(*make_projection(file.path()), uniform_frame(23666));
    const long double expected = 23666 * 0.0229L / std::sqrt(c.x * c.x + c.y * c.y + 1.0L) - 23.97L;
    const double actual = depth->mm.at<float>(c.v, c.u);
    EXPECT_NEAR(actual, static_cast<double>(expected), kMm)
        << "pixel (" << c.u << ", " << c.v << ")";
    // Ignoring the distortion would be millimetres off, so the test tells the two apart.
    const long double xd = distorted.x;
    const long double yd = distorted.y;
    const long double ignored = 23666 * 0.0229L / std::sqrt(xd * xd + yd * yd + 1.0L) - 23.97L;
    EXPECT_GT(std::abs(actual - static_cast<double>(ignored)), 1.0);
  }
}

TEST(DepthProjection, AnyImageWidthAndRowLayoutGiveEq1) {
  // 13 x 3 pixels (not a whole number of SIMD vectors), as a continuous image and as a
  // view into a larger one (rows apart in memory); principal point (6, 1).
  json rig = testing::paper_rig_document();
  rig["depth_camera"]["width"] = 13;
  rig["depth_camera"]["height"] = 3;
  rig["depth_camera"]["cx"] = 6.0;
  rig["depth_camera"]["cy"] = 1.0;
  rig["depth_camera"]["fx"] = 10.0;
  rig["depth_camera"]["fy"] = 12.0;
  const CalibrationFile file(rig);
  const auto stage = make_projection(file.path());
  cv::Mat larger(5, 20, CV_16UC1, cv::Scalar(0));
  cv::randu(larger, 1, 65536);
  larger.at<std::uint16_t>(2, 7) = 0;  // no measurement in the middle of the view
  for (const cv::Mat& gray :
       {larger(cv::Rect(2, 1, 13, 3)), larger(cv::Rect(2, 1, 13, 3)).clone()}) {
    RawTofFrame raw;
    raw.gray = gray;
    const auto depth = project(*stage, raw);
    for (int v = 0; v < 3; ++v) {
      for (int u = 0; u < 13; ++u) {
        const std::uint16_t g = gray.at<std::uint16_t>(v, u);
        const long double x = (u - 6.0L) / 10.0L;
        const long double y = (v - 1.0L) / 12.0L;
        const float z = depth->mm.at<float>(v, u);
        if (g == 0) {
          EXPECT_TRUE(std::isnan(z)) << "pixel (" << u << ", " << v << ")";
          continue;
        }
        // Gray values up to 65535 reach 1500 mm, where float32 is spaced 1.2e-4 mm.
        EXPECT_NEAR(z, static_cast<double>(g * 0.0229L / std::sqrt(x * x + y * y + 1) - 23.97L),
                    2 * kMm)
            << "pixel (" << u << ", " << v << ")";
      }
    }
  }
}

TEST(DepthProjection, AFrameOfAnotherSizeIsRefusedWithBothSizes) {
  const auto stage = make_projection(kPaperRig);
  try {
    project(*stage, uniform_frame(23666, 320, 240));
    FAIL() << "a 320x240 frame was accepted";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()), "raw ToF frame is 320x240 px but the calibration " +
                                             kPaperRig.string() + " is for 640x480 px");
  }
}

TEST(DepthProjection, AFrameOfAnotherPixelTypeIsRefused) {
  const auto stage = make_projection(kPaperRig);
  RawTofFrame raw;
  raw.gray = cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0));
  try {
    project(*stage, raw);
    FAIL() << "a float frame was accepted";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "raw ToF frame has pixel type CV_32FC1; expected CV_16UC1 (16-bit gray)");
  }
}

TEST(DepthProjection, ABadCalibrationIsRefusedAtConstructionWithTheFieldNamed) {
  json zero_focal = testing::paper_rig_document();
  zero_focal["depth_camera"]["fx"] = 0;
  const CalibrationFile zero_focal_file(zero_focal);
  EXPECT_EQ(construction_error(zero_focal_file.path()),
            zero_focal_file.path().string() + ":/depth_camera/fx: expected a number > 0, got 0");

  // k1 = -2 folds the image's outer part back onto itself: no inverse there.
  json folded = testing::paper_rig_document();
  folded["depth_camera"]["distortion"] = {-2.0, 0, 0, 0, 0};
  const CalibrationFile folded_file(folded);
  EXPECT_EQ(construction_error(folded_file.path())
                .rfind(folded_file.path().string() +
                           ":/depth_camera/distortion: the lens distortion cannot be inverted at "
                           "pixel (",
                       0),
            0u)
      << construction_error(folded_file.path());

  EXPECT_EQ(construction_error("/nonexistent/rig.calib.json"),
            "/nonexistent/rig.calib.json: cannot read calibration file");
}

TEST(DepthProjection, OutputBuffersAreReusedInSteadyState) {
  const auto stage = make_projection(kPaperRig);
  const float* first = nullptr;
  {
    const auto depth = project(*stage, uniform_frame(23666));
    first = depth->mm.ptr<float>();
  }  // the only holder drops the message: the pool may hand it out again
  const auto depth = project(*stage, uniform_frame(30000));
  EXPECT_EQ(depth->mm.ptr<float>(), first);
  EXPECT_NEAR(depth->mm.at<float>(240, 313), static_cast<double>(eq1(30000, 313, 240)), kMm);
}

// A saturated ToF image once gave 1440.7 mm valid (issue #14): the sensor's ceiling says
// nothing about where the surface is.
TEST(DepthProjection, GrayAtOrAboveTheSaturationIsNoDepth) {
  const auto stage = make_projection(kPaperRig);
  RawTofFrame raw = uniform_frame(65535);
  raw.gray.at<std::uint16_t>(240, 313) = 65534;
  const auto depth = project(*stage, std::move(raw));
  EXPECT_TRUE(std::isnan(depth->mm.at<float>(0, 0)));
  EXPECT_NEAR(depth->mm.at<float>(240, 313), static_cast<double>(eq1(65534, 313, 240)), kMm);

  const auto lower = make_projection(kPaperRig, 60000);
  RawTofFrame below = uniform_frame(60000);
  below.gray.at<std::uint16_t>(240, 313) = 59999;
  const auto clipped = project(*lower, std::move(below));
  EXPECT_TRUE(std::isnan(clipped->mm.at<float>(0, 0)));
  EXPECT_NEAR(clipped->mm.at<float>(240, 313), static_cast<double>(eq1(59999, 313, 240)), kMm);
}

class LogCapture {
 public:
  LogCapture()
      : previous_(set_log_handler([this](LogLevel level, std::string_view, std::string_view text) {
          if (level == LogLevel::kWarning) warnings.emplace_back(text);
        })) {}
  ~LogCapture() { set_log_handler(previous_); }

  std::vector<std::string> warnings;

 private:
  LogHandler previous_;
};

// Without a file named, the stage uses the calibration the frame carries, and its depth
// image carries it on.
TEST(DepthProjection, AFrameCarriesItsCalibration) {
  const auto stage = make_projection("");
  RawTofFrame raw = uniform_frame(23666);
  raw.rig = std::make_shared<const RigCalibration>(load_calibration(kPaperRig));
  const auto rig = raw.rig;
  const auto depth = project(*stage, std::move(raw));
  EXPECT_NEAR(depth->mm.at<float>(0, 639), static_cast<double>(eq1(23666, 639, 0)), kMm);
  EXPECT_EQ(depth->rig, rig);
}

TEST(DepthProjection, NoCalibrationAnywhereIsAnErrorSayingSo) {
  const auto stage = make_projection("");
  try {
    project(*stage, uniform_frame(23666));
    FAIL() << "projected";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "the frame carries no rig calibration and parameter 'calibration' names none: "
                 "name the rig's calibration file, or use a source whose frames carry one (a "
                 "recording, the simulator, or a camera source given its 'calibration')");
  }
}

// A file named overrides the frame's calibration, never silently: one warning per
// calibration carried, naming what differs.
TEST(DepthProjection, ANamedFileOverridesTheFramesCalibrationLoudly) {
  json other = testing::paper_rig_document();
  other["depth_camera"]["gray_to_mm"] = 0.025;
  const CalibrationFile carried_file(other);
  const auto carried =
      std::make_shared<const RigCalibration>(load_calibration(carried_file.path()));
  const auto stage = make_projection(kPaperRig);
  LogCapture log;
  for (int frame = 0; frame < 3; ++frame) {
    RawTofFrame raw = uniform_frame(23666);
    raw.rig = carried;
    const auto depth = project(*stage, std::move(raw));
    EXPECT_NEAR(depth->mm.at<float>(0, 0), static_cast<double>(eq1(23666, 0, 0)), kMm);
  }
  EXPECT_EQ(log.warnings,
            std::vector<std::string>{
                "parameter 'calibration' (" + kPaperRig.string() +
                ") overrides the calibration the frames carry (" + carried_file.path().string() +
                "), which differs: /depth_camera/gray_to_mm: 0.0229 against 0.025"});
}

TEST(DepthProjection, DescriptorDeclaresTheContract) {
  const StageDescriptor d = describe_projection();
  EXPECT_EQ(d.type, "depth.projection");
  ASSERT_EQ(d.inputs.size(), 1u);
  EXPECT_EQ(d.inputs[0].name, "raw");
  EXPECT_EQ(d.inputs[0].type, RawTofFrame::kTypeName);
  ASSERT_EQ(d.outputs.size(), 1u);
  EXPECT_EQ(d.outputs[0].name, "depth");
  EXPECT_EQ(d.outputs[0].type, DepthImage::kTypeName);
  ASSERT_NE(d.param("calibration"), nullptr);
  EXPECT_EQ(d.param("calibration")->type, ParamType::kPath);
  EXPECT_FALSE(d.param("calibration")->required());  // "": the frames' own
  EXPECT_EQ(d.param("calibration")->default_value, "");
  ASSERT_NE(d.param("saturated_gray"), nullptr);
  EXPECT_EQ(d.param("saturated_gray")->default_value, 65535);
  EXPECT_EQ(d.concurrency, Concurrency::kParallel);
}

}  // namespace
}  // namespace tilth::depth
