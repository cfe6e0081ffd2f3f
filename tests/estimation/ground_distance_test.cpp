// estimation.ground_distance: the median and trimmed mean of soil depths with noise and
// outliers against their closed forms for a normal sample, exact statistics on small
// regions, the validity rules with their reasons, and the region of interest.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimators.h"
#include "source_tree.h"
#include "synthetic_ground.h"
#include "tilth/log.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/testing/stage_harness.h"

namespace tilth::estimation {
namespace {

using nlohmann::json;
using testing::GroundScene;
using testing::TransformHarness;

const std::filesystem::path kPaperRig = testing::paper_rig_path();
const cv::Rect kDefaultRoi(160, 120, 320, 240);  // the middle half of 640x480
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

const DepthCameraCalibration& paper_camera() {
  static const DepthCameraCalibration camera = load_calibration(kPaperRig).depth;
  return camera;
}

std::shared_ptr<DepthImage> depth_message(const cv::Mat& mm) {
  auto message = std::make_shared<DepthImage>();
  message->mm = mm;
  return message;
}

GroundDistance estimate(const cv::Mat& soil_mm, const json& params = json::object()) {
  TransformHarness stage(describe_ground_distance(), params);
  return stage.run({depth_message(soil_mm)})[0].get<GroundDistance>();
}

std::string construction_error(const json& params) {
  try {
    TransformHarness stage(describe_ground_distance(), params);
  } catch (const Error& error) {
    return error.what();
  }
  return "constructed";
}

double normal_cdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }
double normal_pdf(double x) { return std::exp(-0.5 * x * x) / std::sqrt(2.0 * std::numbers::pi); }
double normal_quantile(double p) {
  double low = -10.0;
  double high = 10.0;
  for (int i = 0; i < 100; ++i)
    (normal_cdf(0.5 * (low + high)) < p ? low : high) = 0.5 * (low + high);
  return 0.5 * (low + high);
}

// A flat soil at 518 mm with 2 mm noise, and a share of pixels 20-80 mm nearer (residue
// taken for soil). The outliers all lie below every inlier (20 mm is 10 sigma), so each
// order statistic of the mixture is a known order statistic of the normal inliers.
class NoisySoilWithOutliers : public ::testing::Test {
 protected:
  static constexpr double kNoiseMm = 2.0;
  static constexpr double kOutlierFraction = 0.2;

  NoisySoilWithOutliers() {
    GroundScene scene;
    scene.noise_mm = kNoiseMm;
    scene.outlier_fraction = kOutlierFraction;
    cv::Mat outliers;
    depth_ = testing::render(scene, paper_camera(), &outliers);
    n_ = kDefaultRoi.area();
    n_out_ = cv::countNonZero(outliers(kDefaultRoi));
    n_in_ = n_ - n_out_;
  }

  // The value at quantile p of the inliers.
  double inlier_quantile(double p) const { return 518.0 + kNoiseMm * normal_quantile(p); }

  cv::Mat depth_;
  int n_ = 0;
  int n_out_ = 0;
  int n_in_ = 0;
};

// Tolerance 0.04 mm: four standard errors of a sample quantile near the median of
// ~61 000 normal inliers (sigma sqrt(q (1 - q) / n) / pdf(quantile) = 0.010 mm).
TEST_F(NoisySoilWithOutliers, MedianIsTheMixturesMedianAndSpreadItsScaledMad) {
  const GroundDistance out = estimate(depth_);

  ASSERT_TRUE(out.valid) << out.invalid_reason;
  const double q = (0.5 * n_ - n_out_) / n_in_;  // the median's rank among the inliers
  const double expected_mm = inlier_quantile(q);
  EXPECT_NEAR(out.distance_mm, expected_mm, 0.04);
  // The outliers pull the median 0.64 mm nearer; the tolerance tells that apart.
  EXPECT_LT(expected_mm, 518.0 - 0.5);

  // Half of all pixels lie within t of the median: only inliers can (outliers are 10+ mm off).
  const double delta = (expected_mm - 518.0) / kNoiseMm;
  double low = 0.0;
  double high = 10.0;
  for (int i = 0; i < 100; ++i) {
    const double t = 0.5 * (low + high);
    const double within = n_in_ * (normal_cdf(t - delta) - normal_cdf(-t - delta)) / n_;
    (within < 0.5 ? low : high) = t;
  }
  EXPECT_NEAR(out.spread_mm, 1.4826 * kNoiseMm * low, 0.04);

  EXPECT_EQ(out.soil_pixels, kDefaultRoi.area());
  EXPECT_DOUBLE_EQ(out.soil_fraction, 1.0);
  // docs/estimation.md: full coverage, so the confidence is 1 / (1 + (spread / 10 mm)^2).
  EXPECT_DOUBLE_EQ(out.confidence, 1.0 / (1.0 + std::pow(out.spread_mm / 10.0, 2)));
}

// The mean of a normal sample truncated to quantiles [qa, qb] is
// mu + sigma (pdf(a) - pdf(b)) / (qb - qa). Tolerance as for the median: the trimmed
// mean of ~46 000 inliers has a standard error near 0.008 mm.
TEST_F(NoisySoilWithOutliers, TrimmedMeanIsTheTruncatedNormalMean) {
  constexpr double kTrim = 0.25;
  const GroundDistance out =
      estimate(depth_, {{"statistic", "trimmed_mean"}, {"trim_fraction", kTrim}});

  ASSERT_TRUE(out.valid) << out.invalid_reason;
  const int cut = static_cast<int>(kTrim * n_);
  ASSERT_GT(cut, n_out_);  // every outlier is trimmed
  const double qa = static_cast<double>(cut - n_out_) / n_in_;
  const double qb = static_cast<double>(n_ - cut - n_out_) / n_in_;
  const double a = normal_quantile(qa);
  const double b = normal_quantile(qb);
  const double expected_mm = 518.0 + kNoiseMm * (normal_pdf(a) - normal_pdf(b)) / (qb - qa);
  EXPECT_NEAR(out.distance_mm, expected_mm, 0.04);
  // 0.1 mm from the median here: the tolerance tells the statistics apart.
  EXPECT_GT(std::abs(expected_mm - inlier_quantile((0.5 * n_ - n_out_) / n_in_)), 0.08);
}

// The statistics found through a histogram of the depths are those of the sorted depths,
// to the last bit, with 40 % of the region masked as residue and 2 % infinite (no soil).
TEST_F(NoisySoilWithOutliers, StatisticsAreThoseOfTheSortedDepths) {
  cv::Mat soil = depth_.clone();
  cv::Mat residue(soil.size(), CV_8UC1);
  cv::RNG(2).fill(residue, cv::RNG::UNIFORM, 0, 100);
  soil.setTo(kNaN, residue < 40);
  soil.setTo(std::numeric_limits<float>::infinity(), residue == 50);
  soil.setTo(-std::numeric_limits<float>::infinity(), residue == 51);
  std::vector<float> depths;
  for (int v = kDefaultRoi.y; v < kDefaultRoi.y + kDefaultRoi.height; ++v) {
    for (int u = kDefaultRoi.x; u < kDefaultRoi.x + kDefaultRoi.width; ++u) {
      if (std::isfinite(soil.at<float>(v, u))) depths.push_back(soil.at<float>(v, u));
    }
  }
  const auto median_of = [](std::vector<float> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 == 1 ? double{values[n / 2]}
                      : 0.5 * (double{values[n / 2 - 1]} + double{values[n / 2]});
  };
  const double median_mm = median_of(depths);
  std::vector<float> deviations;
  for (const float depth : depths) {
    deviations.push_back(static_cast<float>(std::abs(depth - median_mm)));
  }
  std::vector<float> sorted = depths;
  std::sort(sorted.begin(), sorted.end());
  const auto cut = static_cast<std::ptrdiff_t>(0.25 * static_cast<double>(sorted.size()));
  const double trimmed_mm = std::accumulate(sorted.begin() + cut, sorted.end() - cut, 0.0) /
                            static_cast<double>(sorted.size() - 2 * cut);

  const GroundDistance median = estimate(soil);
  const GroundDistance trimmed =
      estimate(soil, {{"statistic", "trimmed_mean"}, {"trim_fraction", 0.25}});
  ASSERT_TRUE(median.valid) << median.invalid_reason;
  ASSERT_TRUE(trimmed.valid) << trimmed.invalid_reason;
  EXPECT_EQ(median.soil_pixels, static_cast<std::int64_t>(depths.size()));
  EXPECT_EQ(median.distance_mm, median_mm);
  EXPECT_EQ(trimmed.distance_mm, trimmed_mm);
  EXPECT_EQ(median.spread_mm, 1.4826 * median_of(deviations));
  EXPECT_EQ(trimmed.spread_mm, median.spread_mm);
}

// Depths i^2 for i = 1..100 in a 10x10 region, larger values outside it.
cv::Mat squares_in_corner() {
  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(1e6));
  for (int i = 0; i < 100; ++i)
    depth.at<float>(i / 10, i % 10) = static_cast<float>((i + 1) * (i + 1));
  return depth;
}

// The squares are no ground: these tests pin the statistics, so the gates stand aside.
const json kCornerRoi = {{"roi", {{"x", 0}, {"y", 0}, {"width", 10}, {"height", 10}}},
                         {"min_soil_pixels", 1},
                         {"max_distance_mm", 1e5},
                         {"max_spread_mm", 1e5},
                         {"min_confidence", 0}};

TEST(GroundDistance, MedianOfAnEvenCountAveragesTheMiddlePair) {
  EXPECT_DOUBLE_EQ(estimate(squares_in_corner(), kCornerRoi).distance_mm,
                   (50 * 50 + 51 * 51) / 2.0);
}

TEST(GroundDistance, TrimmedMeanDropsTheTrimmedShareAtEachEnd) {
  json params = kCornerRoi;
  params["statistic"] = "trimmed_mean";
  params["trim_fraction"] = 0.1;
  double sum = 0.0;
  for (int i = 11; i <= 90; ++i) sum += i * i;
  EXPECT_DOUBLE_EQ(estimate(squares_in_corner(), params).distance_mm, sum / 80.0);
}

// Soil only in a 60x40 patch of the 320x240 region: 2400 px, 3.125 %.
cv::Mat soil_patch() {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(kNaN));
  depth(cv::Rect(300, 200, 60, 40)).setTo(518.0);
  return depth;
}

TEST(GroundDistance, TooLittleVisibleSoilIsInvalidNeverAGuess) {
  const GroundDistance out = estimate(soil_patch());
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.cause, InvalidCause::kTooLittleSoil);
  EXPECT_EQ(out.invalid_reason, "too little visible soil: 3.1 % of the region of interest < 5.0 %");
  EXPECT_EQ(out.distance_mm, 0.0);
  EXPECT_EQ(out.confidence, 0.0);
  EXPECT_EQ(out.soil_pixels, 2400);
  EXPECT_DOUBLE_EQ(out.soil_fraction, 2400.0 / kDefaultRoi.area());
}

TEST(GroundDistance, TooFewSoilPixelsIsInvalid) {
  const GroundDistance out =
      estimate(soil_patch(), {{"min_soil_fraction", 0.01}, {"min_soil_pixels", 3000}});
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.invalid_reason, "too little visible soil: 2400 px < 3000 px");
  EXPECT_EQ(out.distance_mm, 0.0);
}

TEST(GroundDistance, ExactlyTheMinimumSoilFractionIsValid) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(kNaN));
  depth(cv::Rect(300, 200, 96, 40)).setTo(518.0);  // 3840 px = 5 % of the region
  const GroundDistance out = estimate(depth);
  EXPECT_TRUE(out.valid) << out.invalid_reason;
  EXPECT_EQ(out.distance_mm, 518.0);
  // Coverage 0.05 / 0.25 and no spread.
  EXPECT_DOUBLE_EQ(out.confidence, 0.2);
}

// Half the region at 500 mm, half at 540 mm: median 520, every deviation 20 mm
// (plausibility_test.cpp has the spread's limit).
TEST(GroundDistance, SpreadIsTheScaledMedianAbsoluteDeviation) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(500.0));
  depth(cv::Rect(0, 0, 320, 480)).setTo(540.0);
  const GroundDistance out = estimate(depth);
  EXPECT_TRUE(out.valid);
  EXPECT_EQ(out.distance_mm, 520.0);
  EXPECT_DOUBLE_EQ(out.spread_mm, 1.4826 * 20.0);
}

class WarningCapture {
 public:
  WarningCapture()
      : previous_(
            set_log_handler([this](LogLevel level, std::string_view, std::string_view message) {
              if (level == LogLevel::kWarning) warnings.emplace_back(message);
            })) {}
  ~WarningCapture() { set_log_handler(previous_); }

  std::vector<std::string> warnings;

 private:
  LogHandler previous_;
};

TEST(GroundDistance, RegionReachingOutsideTheImageIsClippedWithOneWarning) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(518.0));
  depth(cv::Rect(600, 400, 40, 80)).setTo(400.0);
  WarningCapture log;
  TransformHarness stage(describe_ground_distance(),
                         {{"roi", {{"x", 600}, {"y", 400}, {"width", 100}, {"height", 200}}}});
  for (std::uint64_t frame = 0; frame < 2; ++frame) {
    const GroundDistance out = stage.run({depth_message(depth)}, frame)[0].get<GroundDistance>();
    EXPECT_EQ(out.distance_mm, 400.0);
    EXPECT_EQ(out.soil_pixels, 40 * 80);
    EXPECT_EQ(out.soil_fraction, 1.0);
  }
  EXPECT_EQ(log.warnings, std::vector<std::string>{"roi x 600, y 400, 100x200 reaches outside the "
                                                   "640x480 image; using x 600, y 400, 40x80"});
}

TEST(GroundDistance, RegionOutsideTheImageIsAnError) {
  TransformHarness stage(describe_ground_distance(),
                         {{"roi", {{"x", 700}, {"y", 0}, {"width", 10}, {"height", 10}}}});
  const cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(518.0));
  try {
    stage.run({depth_message(depth)});
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "parameter 'roi': x 700, y 0, 10x10 lies outside the 640x480 depth image");
  }
}

TEST(GroundDistance, RegionParameterErrorsSayWhatIsExpected) {
  EXPECT_EQ(construction_error({{"roi", {1, 2, 3, 4}}}),
            "parameter 'roi': expected null, \"image\", \"middle_half\" or {\"x\", \"y\", "
            "\"width\", \"height\"} in pixels, got [1,2,3,4]");
  EXPECT_EQ(construction_error({{"roi", "middle"}}),
            "parameter 'roi': expected null, \"image\", \"middle_half\" or {\"x\", \"y\", "
            "\"width\", \"height\"} in pixels, got \"middle\"");
  EXPECT_EQ(construction_error({{"roi", {{"x", 0}, {"y", 0}, {"width", 10}}}}),
            "parameter 'roi': missing field \"height\"");
  EXPECT_EQ(construction_error({{"roi", {{"x", 0}, {"y", 0}, {"w", 10}, {"height", 10}}}}),
            "parameter 'roi': no field \"w\" (expected x, y, width, height)");
  EXPECT_EQ(construction_error({{"roi", {{"x", 0.5}, {"y", 0}, {"width", 10}, {"height", 10}}}}),
            "parameter 'roi': \"x\" must be an integer number of pixels, got 0.5");
  EXPECT_EQ(construction_error({{"roi", {{"x", 0}, {"y", 0}, {"width", 0}, {"height", 10}}}}),
            "parameter 'roi': \"width\" must be >= 1 px, got 0");
}

}  // namespace
}  // namespace tilth::estimation
