// The statistics of tilth ab against values computed elsewhere: Student's t quantiles
// (scipy.stats.t.ppf), the paper's Table 2 errors, mask ratios, histogram bins, and the
// judgement of frames against their truth.
#include <gtest/gtest.h>

#include "figures.h"
#include "statistics.h"
#include "tilth/error.h"

namespace tilth::ab {
namespace {

TEST(StudentT, MatchesScipyQuantiles) {
  EXPECT_NEAR(student_t_quantile(0.975, 1), 12.706204736432095, 1e-9);
  EXPECT_NEAR(student_t_quantile(0.975, 4), 2.7764451051977987, 1e-11);
  EXPECT_NEAR(student_t_quantile(0.975, 30), 2.0422724563012373, 1e-11);
  EXPECT_NEAR(student_t_quantile(0.975, 1000), 1.9623390808264074, 1e-11);
  EXPECT_NEAR(student_t_quantile(0.025, 4), -2.7764451051977996, 1e-11);
  EXPECT_THROW(student_t_quantile(1.0, 4), Error);
  EXPECT_THROW(student_t_quantile(0.975, 0), Error);
}

TEST(ErrorStats, PaperTable2Errors) {
  // The paper's cases A-E: errors -0.8 ... -2.2 mm; it reports mean -1.66 and a 95 %
  // interval of about [-2.32, -1.00].
  const ErrorStats stats = error_stats({-0.8, -1.6, -1.8, -1.9, -2.2});
  EXPECT_EQ(stats.count, 5u);
  EXPECT_NEAR(stats.mean_mm, -1.66, 1e-12);
  EXPECT_NEAR(*stats.std_mm, 0.5272570530585627, 1e-12);
  EXPECT_NEAR(*stats.ci95_low_mm, -2.3146761005818304, 1e-10);
  EXPECT_NEAR(*stats.ci95_high_mm, -1.0053238994181697, 1e-10);
  EXPECT_NEAR(stats.mean_abs_mm, 1.66, 1e-12);
  EXPECT_NEAR(stats.max_abs_mm, 2.2, 1e-12);
  EXPECT_NEAR(stats.rms_mm, 1.725688268488837, 1e-12);
}

TEST(ErrorStats, OneValueHasNoSpread) {
  const ErrorStats stats = error_stats({0.5});
  EXPECT_EQ(stats.count, 1u);
  EXPECT_DOUBLE_EQ(stats.mean_mm, 0.5);
  EXPECT_FALSE(stats.std_mm);
  EXPECT_FALSE(stats.ci95_low_mm);
  EXPECT_EQ(error_stats({}).count, 0u);
}

TEST(MaskCounts, RatiosAndEmptyDenominators) {
  MaskCounts counts{.tp = 30, .fp = 10, .fn = 20, .tn = 40, .unknown = 5};
  EXPECT_DOUBLE_EQ(*counts.iou(), 30.0 / 60.0);
  EXPECT_DOUBLE_EQ(*counts.precision(), 30.0 / 40.0);
  EXPECT_DOUBLE_EQ(*counts.recall(), 30.0 / 50.0);
  counts += MaskCounts{.tp = 10, .fp = 0, .fn = 0, .tn = 1, .unknown = 1};
  EXPECT_EQ(counts.tp, 40);
  EXPECT_EQ(counts.unknown, 6);
  const MaskCounts soil_only{.tp = 0, .fp = 0, .fn = 0, .tn = 100, .unknown = 0};
  EXPECT_FALSE(soil_only.iou());
  EXPECT_FALSE(soil_only.precision());
  EXPECT_FALSE(soil_only.recall());
}

TEST(Histogram, RoundWidthsCoverEveryValue) {
  const std::vector<double> errors{-0.83, -0.25, 0.05, 0.41, 1.07};
  const HistogramBins bins = histogram_bins(errors, 20);
  EXPECT_DOUBLE_EQ(bins.width_mm, 0.1);  // span 1.9 / 20 = 0.095 -> 0.1
  EXPECT_NEAR(bins.first_edge_mm, -0.9, 1e-12);
  EXPECT_EQ(bins.count, 20u);
  const auto counts = histogram(bins, errors);
  EXPECT_EQ(counts[0], 1u);   // -0.83 in [-0.9, -0.8)
  EXPECT_EQ(counts[6], 1u);   // -0.25
  EXPECT_EQ(counts[9], 1u);   // 0.05
  EXPECT_EQ(counts[13], 1u);  // 0.41
  EXPECT_EQ(counts[19], 1u);  // 1.07
  EXPECT_EQ(histogram_bins({}, 20).count, 0u);
  EXPECT_EQ(histogram_bins({2.0, 2.0}, 20).count, 1u);
}

FrameRecord record(std::int64_t time_ns, bool valid, std::optional<double> distance,
                   std::optional<double> truth, std::optional<double> soil) {
  FrameRecord r;
  r.device_timestamp_ns = time_ns;
  r.measured = true;
  r.valid = valid;
  r.distance_mm = distance;
  r.truth_mm = truth;
  r.truth_soil_fraction = soil;
  return r;
}

TEST(JudgeFrames, MissedFalseValidAndErrors) {
  const auto frames = judge_frames(
      {record(1'000'000'000, true, 518.5, 518.0, 0.4),    // valid, error +0.5
       record(1'033'000'000, false, {}, 518.0, 0.3),      // missed
       record(1'066'000'000, true, 470.0, 518.0, 0.001),  // no visible soil, reported valid
       record(1'100'000'000, false, {}, 518.0, 0.0),      // no visible soil, invalid: right
       record(1'133'000'000, true, 517.0, {}, {})},       // no truth
      0.01);
  ASSERT_EQ(frames.size(), 5u);
  EXPECT_DOUBLE_EQ(frames[1].time_s, 0.033);
  EXPECT_EQ(frames[0].expected, Expectation::kValid);
  EXPECT_DOUBLE_EQ(*frames[0].error_mm, 0.5);
  EXPECT_TRUE(frames[1].missed);
  EXPECT_EQ(frames[2].expected, Expectation::kNoVisibleSoil);
  EXPECT_TRUE(frames[2].false_valid);
  EXPECT_DOUBLE_EQ(*frames[2].error_mm, -48.0);
  EXPECT_FALSE(frames[3].false_valid);
  EXPECT_FALSE(frames[3].missed);
  EXPECT_EQ(frames[4].expected, Expectation::kUnknown);
  EXPECT_FALSE(frames[4].error_mm);

  const Figures figures = figures_of({&frames});
  EXPECT_EQ(figures.frames, 5u);
  EXPECT_EQ(figures.valid, 3u);
  EXPECT_EQ(figures.expected_valid, 2u);
  EXPECT_EQ(figures.no_visible_soil, 2u);
  EXPECT_EQ(figures.missed, 1u);
  EXPECT_EQ(figures.false_valid, 1u);
  EXPECT_EQ(figures.error.count, 2u);
  EXPECT_DOUBLE_EQ(figures.error.mean_mm, (0.5 - 48.0) / 2);
  EXPECT_FALSE(figures.mask);
}

}  // namespace
}  // namespace tilth::ab
