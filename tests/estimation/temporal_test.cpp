// estimation.temporal on a pass over stepped soil at 30 frames/s, as an estimator reports
// it: 0.3 mm of noise, steps of +6 and -5 mm, single frames far off (straw taken for
// soil), and gaps without a distance (cover), short and long. The filter follows each
// step one frame late and exactly, never passes an outlier, holds over short gaps with
// the held value's age, gives up after max_hold_ms, and smooths with the lag it states.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimators.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/testing/stage_harness.h"

namespace tilth::estimation {
namespace {

using nlohmann::json;
using testing::TransformHarness;

constexpr std::int64_t kPeriodNs = 33'333'333;  // 30 frames/s
constexpr double kPeriodMs = kPeriodNs / 1e6;

GroundDistance valid_at(double distance_mm) {
  GroundDistance in;
  in.valid = true;
  in.distance_mm = distance_mm;
  in.soil_fraction = 0.4;
  in.confidence = 0.9;
  return in;
}

GroundDistance invalid() {
  GroundDistance in;
  in.invalidate(InvalidCause::kTooLittleSoil, "too little soil visible");
  return in;
}

class TemporalFilter {
 public:
  explicit TemporalFilter(const json& params = json::object())
      : stage_(describe_temporal(), params) {}

  GroundDistance next(const GroundDistance& in) {
    FrameInfo info;
    info.sequence = info.frame_id = frames_;
    info.host_timestamp_ns =
        1'700'000'000'000'000'000 + static_cast<std::int64_t>(frames_) * kPeriodNs + shift_ns_;
    ++frames_;
    return stage_.run({std::make_shared<GroundDistance>(in)}, info)[0].get<GroundDistance>();
  }

  // Moves the capture clock: a replay that loops, a clock set back.
  void shift_clock(std::int64_t ns) { shift_ns_ += ns; }

 private:
  TransformHarness stage_;
  std::uint64_t frames_ = 0;
  std::int64_t shift_ns_ = 0;
};

// The soil under the tool point along the pass: 518 mm, 524 from frame 40, 519 from 80.
double soil_at(int frame) { return frame < 40 ? 518.0 : frame < 80 ? 524.0 : 519.0; }

TEST(Temporal, FollowsEachStepOneFrameLateAndNeverPassesASingleFrameOutlier) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  const std::vector<int> outliers = {12, 33, 61, 95};  // 9-15 mm nearer: straw
  TemporalFilter filter;
  double shown = 0.0;
  for (int frame = 0; frame < 120; ++frame) {
    const bool outlier = std::find(outliers.begin(), outliers.end(), frame) != outliers.end();
    const double measured =
        outlier ? soil_at(frame) - 9.0 - frame % 7 : soil_at(frame) + noise(random);
    const GroundDistance out = filter.next(valid_at(measured));
    ASSERT_TRUE(out.valid) << "frame " << frame;
    const bool step_frame = frame == 40 || frame == 80;
    if (outlier || step_frame) {
      // The frame before's distance, held, one period old.
      EXPECT_TRUE(out.held) << "frame " << frame;
      EXPECT_DOUBLE_EQ(out.distance_mm, shown) << "frame " << frame;
      EXPECT_NEAR(out.held_ms, kPeriodMs, 1e-6) << "frame " << frame;
    } else {
      // The new level at once on the frame after a step: it agrees with the step frame.
      EXPECT_FALSE(out.held) << "frame " << frame;
      EXPECT_DOUBLE_EQ(out.distance_mm, measured) << "frame " << frame;
      EXPECT_NEAR(out.distance_mm, soil_at(frame), 1.5) << "frame " << frame;
    }
    shown = out.distance_mm;
  }
}

TEST(Temporal, ConfirmFramesOneFollowsEveryJumpAtOnce) {
  TemporalFilter filter(json{{"confirm_frames", 1}});
  filter.next(valid_at(518.0));
  const GroundDistance out = filter.next(valid_at(530.0));
  EXPECT_FALSE(out.held);
  EXPECT_DOUBLE_EQ(out.distance_mm, 530.0);
}

TEST(Temporal, DisagreeingOutliersDoNotMakeAStep) {
  TemporalFilter filter;
  filter.next(valid_at(518.0));
  // Two frames off the track, but 8 mm apart: no step, both held.
  EXPECT_TRUE(filter.next(valid_at(530.0)).held);
  EXPECT_TRUE(filter.next(valid_at(538.0)).held);
  // The third agrees with the second: a step to 538.4.
  const GroundDistance out = filter.next(valid_at(538.4));
  EXPECT_FALSE(out.held);
  EXPECT_DOUBLE_EQ(out.distance_mm, 538.4);
}

TEST(Temporal, HoldsOverAShortGapWithItsAgeAndGivesUpAfterMaxHold) {
  TemporalFilter filter(json{{"max_hold_ms", 200}});
  GroundDistance last = valid_at(521.5);
  last.soil_fraction = 0.31;
  filter.next(last);
  // Six frames (200 ms) of cover: held, aging by a period each frame.
  for (int gap = 1; gap <= 6; ++gap) {
    const GroundDistance out = filter.next(invalid());
    ASSERT_TRUE(out.valid) << "gap frame " << gap;
    EXPECT_TRUE(out.held);
    EXPECT_DOUBLE_EQ(out.distance_mm, 521.5);
    EXPECT_DOUBLE_EQ(out.soil_fraction, 0.31);  // of the measurement held
    EXPECT_NEAR(out.held_ms, gap * kPeriodMs, 1e-6);
  }
  // The seventh is 233 ms after the last distance: passed on as it came.
  GroundDistance out = filter.next(invalid());
  EXPECT_FALSE(out.valid);
  EXPECT_FALSE(out.held);
  EXPECT_EQ(out.cause, InvalidCause::kTooLittleSoil);
  EXPECT_EQ(out.invalid_reason, "too little soil visible");
  EXPECT_EQ(out.distance_mm, 0.0);
  // The track ended with the hold: the next distance starts a new one, however far.
  out = filter.next(valid_at(540.0));
  EXPECT_FALSE(out.held);
  EXPECT_DOUBLE_EQ(out.distance_mm, 540.0);
}

TEST(Temporal, ACaptureTimeBeforeTheTracksLastEndsTheTrack) {
  TemporalFilter filter;
  filter.next(valid_at(518.0));
  filter.shift_clock(-1'000'000'000);
  // Not held with a negative age: passed on invalid, with its own cause.
  const GroundDistance gap = filter.next(invalid());
  EXPECT_FALSE(gap.valid);
  EXPECT_FALSE(gap.held);
  EXPECT_EQ(gap.cause, InvalidCause::kTooLittleSoil);
  // The next distance starts a new track, however far from the old one.
  const GroundDistance restart = filter.next(valid_at(530.0));
  EXPECT_TRUE(restart.valid);
  EXPECT_FALSE(restart.held);
  EXPECT_DOUBLE_EQ(restart.distance_mm, 530.0);
  EXPECT_DOUBLE_EQ(restart.held_ms, 0.0);
}

TEST(Temporal, MaxHoldZeroNeverHolds) {
  TemporalFilter filter(json{{"max_hold_ms", 0}});
  filter.next(valid_at(518.0));
  EXPECT_FALSE(filter.next(invalid()).valid);
}

// A first-order low-pass y += a (x - y), a = 1 - exp(-T / tau), lags a ramp of r per
// frame by r / (exp(T / tau) - 1) once settled: about tau - T/2 in time.
TEST(Temporal, SmoothingLagsARampByItsStatedTimeConstant) {
  constexpr double kTauMs = 100.0;
  constexpr double kSlopeMm = 0.2;  // per frame, under outlier_mm
  TemporalFilter filter(json{{"smoothing_ms", kTauMs}});
  GroundDistance out;
  for (int frame = 0; frame < 60; ++frame) out = filter.next(valid_at(500.0 + kSlopeMm * frame));
  const double lag_mm = 500.0 + kSlopeMm * 59 - out.distance_mm;
  EXPECT_NEAR(lag_mm, kSlopeMm / (std::exp(kPeriodMs / kTauMs) - 1.0), 1e-6);
  EXPECT_NEAR(lag_mm / kSlopeMm * kPeriodMs, kTauMs - kPeriodMs / 2, 1.5);  // in ms
  // A step is followed unsmoothed, once confirmed.
  filter.next(valid_at(520.0));
  EXPECT_DOUBLE_EQ(filter.next(valid_at(520.1)).distance_mm, 520.1);
}

}  // namespace
}  // namespace tilth::estimation
