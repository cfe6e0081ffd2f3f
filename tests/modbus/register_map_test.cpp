// The register block exactly as a PLC reads it: 32-bit values in both word orders,
// scaling, saturation, status bits, and how staleness and age follow the clock.
#include "register_map.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "latest_measurement.h"
#include "tilth/error.h"

namespace tilth::modbus {
namespace {

using std::chrono::microseconds;
using std::chrono::milliseconds;

RegisterValues valid_distance(double distance_mm) {
  RegisterValues values;
  values.valid = true;
  values.camera_ok = true;
  values.stale = false;
  values.distance_mm = distance_mm;
  return values;
}

TEST(RegisterMap, DistanceInBothWordOrders) {
  RegisterValues values = valid_distance(518.23);
  values.soil_fraction = 0.4321;
  values.confidence = 0.8766;
  values.frame_id = 70000;  // 0x00011170
  values.heartbeat = 4242;
  values.age = milliseconds(37);
  // 518.23 mm = 51823 hundredths = 0x0000CA6F; 518.23f = 0x44018EB8.
  EXPECT_EQ(encode(values, WordOrder::kHighFirst),
            (RegisterBlock{0x0000, 0xCA6F, 0x4401, 0x8EB8, 0x0001, 0x1170, 0x0003, 4321, 877, 4242,
                           37, 0}));
  EXPECT_EQ(encode(values, WordOrder::kLowFirst),
            (RegisterBlock{0xCA6F, 0x0000, 0x8EB8, 0x4401, 0x1170, 0x0001, 0x0003, 4321, 877, 4242,
                           37, 0}));
}

TEST(RegisterMap, NegativeAndSaturatedDistances) {
  const RegisterBlock negative = encode(valid_distance(-1.5), WordOrder::kHighFirst);
  EXPECT_EQ(negative[kDistanceHundredthsMm], 0xFFFF);  // -150 = 0xFFFFFF6A
  EXPECT_EQ(negative[kDistanceHundredthsMm + 1], 0xFF6A);
  EXPECT_EQ(negative[kDistanceMm], 0xBFC0);  // -1.5f = 0xBFC00000
  EXPECT_EQ(negative[kDistanceMm + 1], 0x0000);

  const RegisterBlock huge = encode(valid_distance(3e7), WordOrder::kHighFirst);
  EXPECT_EQ(huge[kDistanceHundredthsMm], 0x7FFF);  // int32 max, not wrapped
  EXPECT_EQ(huge[kDistanceHundredthsMm + 1], 0xFFFF);
  EXPECT_EQ(huge[kDistanceMm], 0x4BE4);  // 3e7f = 0x4BE4E1C0
  EXPECT_EQ(huge[kDistanceMm + 1], 0xE1C0);
}

TEST(RegisterMap, NotValidPublishesNoDistance) {
  RegisterValues values;
  values.valid = false;
  values.stale = false;
  values.camera_ok = true;
  values.cause = InvalidCause::kTooLittleSoil;
  values.distance_mm = 518.23;
  values.soil_fraction = 0.031;
  const RegisterBlock block = encode(values, WordOrder::kHighFirst);
  EXPECT_EQ(block[kDistanceHundredthsMm], 0);
  EXPECT_EQ(block[kDistanceHundredthsMm + 1], 0);
  EXPECT_EQ(block[kDistanceMm], 0);
  EXPECT_EQ(block[kDistanceMm + 1], 0);
  EXPECT_EQ(block[kStatus], kCameraOk | kTooLittleSoil);  // 0x0006
  EXPECT_EQ(block[kSoilFraction], 310);
  EXPECT_EQ(block[kInvalidCause], 1);
}

// Each cause sets its status bit and its number (docs/modbus.md), and clears valid's
// distance registers.
TEST(RegisterMap, EachInvalidCauseHasItsBitAndNumber) {
  struct Expected {
    InvalidCause cause;
    std::uint16_t status;
    std::uint16_t number;
  };
  for (const Expected& expected : {Expected{InvalidCause::kTooLittleSoil, 0x0006, 1},
                                   Expected{InvalidCause::kNotOneSurface, 0x0022, 2},
                                   Expected{InvalidCause::kOutOfRange, 0x0022, 3},
                                   Expected{InvalidCause::kLowConfidence, 0x0022, 4},
                                   Expected{InvalidCause::kImageUnusable, 0x0042, 5}}) {
    RegisterValues values;
    values.stale = false;
    values.camera_ok = true;
    values.cause = expected.cause;
    values.distance_mm = 1448.81;
    const RegisterBlock block = encode(values, WordOrder::kHighFirst);
    EXPECT_EQ(block[kStatus], expected.status) << to_string(expected.cause);
    EXPECT_EQ(block[kInvalidCause], expected.number) << to_string(expected.cause);
    EXPECT_EQ(block[kDistanceMm], 0) << to_string(expected.cause);
  }
}

TEST(RegisterMap, StatusBitsEach) {
  RegisterValues values;
  values.stale = false;
  EXPECT_EQ(encode(values, WordOrder::kHighFirst)[kStatus], 0x0000);
  values.stale = true;
  EXPECT_EQ(encode(values, WordOrder::kHighFirst)[kStatus], 0x0008);
  values.pipeline_error = true;
  EXPECT_EQ(encode(values, WordOrder::kHighFirst)[kStatus], 0x0018);
  values = valid_distance(1.0);
  EXPECT_EQ(encode(values, WordOrder::kHighFirst)[kStatus], 0x0003);
}

TEST(RegisterMap, ScaledValuesAreClampedAndRounded) {
  RegisterValues values;
  values.soil_fraction = 1.2;
  values.confidence = -0.1;
  values.age = milliseconds(70000);
  RegisterBlock block = encode(values, WordOrder::kHighFirst);
  EXPECT_EQ(block[kSoilFraction], 10000);
  EXPECT_EQ(block[kConfidence], 0);
  EXPECT_EQ(block[kAgeMs], 65535);

  values.soil_fraction = std::numeric_limits<double>::quiet_NaN();
  values.confidence = 0.99951;
  values.age = milliseconds::max();
  block = encode(values, WordOrder::kHighFirst);
  EXPECT_EQ(block[kSoilFraction], 0);
  EXPECT_EQ(block[kConfidence], 1000);
  EXPECT_EQ(block[kAgeMs], 65535);
}

TEST(RegisterMap, FrameCounterIsTheLow32BitsOfTheFrameId) {
  RegisterValues values;
  values.frame_id = 0x1'2345'6789;
  const RegisterBlock block = encode(values, WordOrder::kHighFirst);
  EXPECT_EQ(block[kFrameCounter], 0x2345);
  EXPECT_EQ(block[kFrameCounter + 1], 0x6789);
}

TEST(RegisterMap, WordOrderNames) {
  EXPECT_EQ(parse_word_order("big"), WordOrder::kHighFirst);
  EXPECT_EQ(parse_word_order("little"), WordOrder::kLowFirst);
  try {
    parse_word_order("middle");
    FAIL() << "no error";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(), "word_order: expected 'big' or 'little', got 'middle'");
  }
}

class LatestMeasurementTest : public ::testing::Test {
 protected:
  static GroundDistance measured(double distance_mm, bool valid,
                                 InvalidCause cause = InvalidCause::kNone) {
    GroundDistance distance;
    distance.distance_mm = distance_mm;
    distance.valid = valid;
    distance.cause = cause;
    distance.soil_fraction = 0.5;
    distance.confidence = 0.9;
    return distance;
  }

  LatestMeasurement latest_{milliseconds(200)};
  const LatestMeasurement::Clock::time_point t0_ = LatestMeasurement::Clock::now();
};

TEST_F(LatestMeasurementTest, NothingYetIsStaleWithAnAgeOfNever) {
  const RegisterBlock block = encode(latest_.values_at(t0_), WordOrder::kHighFirst);
  EXPECT_EQ(block[kStatus], kStale);
  EXPECT_EQ(block[kAgeMs], 65535);
  EXPECT_EQ(block[kDistanceHundredthsMm + 1], 0);
}

TEST_F(LatestMeasurementTest, ValidUntilTheStaleTimeoutThenStale) {
  latest_.update(7, measured(518.23, true), t0_, milliseconds(12));

  RegisterValues fresh = latest_.values_at(t0_ + milliseconds(200));
  EXPECT_TRUE(fresh.valid);
  EXPECT_FALSE(fresh.stale);
  EXPECT_TRUE(fresh.camera_ok);
  EXPECT_EQ(fresh.age, milliseconds(212));  // capture to arrival, then arrival to now
  EXPECT_EQ(encode(fresh, WordOrder::kHighFirst)[kDistanceHundredthsMm + 1], 0xCA6F);

  RegisterValues old = latest_.values_at(t0_ + milliseconds(201));
  EXPECT_FALSE(old.valid);
  EXPECT_TRUE(old.stale);
  EXPECT_FALSE(old.camera_ok);
  EXPECT_EQ(old.frame_id, 7u);
  const RegisterBlock block = encode(old, WordOrder::kHighFirst);
  EXPECT_EQ(block[kStatus], kStale);
  EXPECT_EQ(block[kDistanceHundredthsMm + 1], 0);
  EXPECT_EQ(block[kAgeMs], 213);
}

// Capture to arrival 12.6 ms, arrival to the reading 0.6 ms: 13.2 ms, shown as 13. Each part
// cut to whole milliseconds first would show 12, a frame younger than it is.
TEST_F(LatestMeasurementTest, TheAgeIsCutToWholeMillisecondsOnceNotPartByPart) {
  latest_.update(7, measured(518.23, true), t0_, microseconds(12600));
  EXPECT_EQ(latest_.values_at(t0_ + microseconds(600)).age, milliseconds(13));
  EXPECT_EQ(latest_.values_at(t0_ + microseconds(399)).age, milliseconds(12));
}

// Stale once the whole milliseconds since arrival pass the timeout (200 ms), so that a
// stale block's age always reads past it.
TEST_F(LatestMeasurementTest, StaleOnlyOnceTheWholeMillisecondsPassTheTimeout) {
  latest_.update(7, measured(518.23, true), t0_, milliseconds(0));
  const RegisterValues last_valid = latest_.values_at(t0_ + microseconds(200900));
  EXPECT_FALSE(last_valid.stale);
  EXPECT_EQ(last_valid.age, milliseconds(200));
  const RegisterValues stale = latest_.values_at(t0_ + microseconds(201000));
  EXPECT_TRUE(stale.stale);
  EXPECT_EQ(stale.age, milliseconds(201));
}

TEST_F(LatestMeasurementTest, AFrameWithoutMeasurementIsAPipelineError) {
  latest_.update(1, measured(500.0, true), t0_, milliseconds(0));
  latest_.update_missing(t0_ + milliseconds(150));
  RegisterValues values = latest_.values_at(t0_ + milliseconds(300));
  // The measurement went stale; frames still arrive, the last one without a result.
  EXPECT_EQ(encode(values, WordOrder::kHighFirst)[kStatus], kCameraOk | kStale | kPipelineError);
  latest_.update(2, measured(501.0, true), t0_ + milliseconds(310), milliseconds(0));
  values = latest_.values_at(t0_ + milliseconds(320));
  EXPECT_EQ(encode(values, WordOrder::kHighFirst)[kStatus], kValid | kCameraOk);
}

// A frame without a measurement clears valid at once, not only after the stale timeout.
TEST_F(LatestMeasurementTest, AFrameWithoutMeasurementClearsValidAtOnce) {
  latest_.update(1, measured(500.0, true), t0_, milliseconds(0));
  latest_.update_missing(t0_ + milliseconds(33));
  EXPECT_EQ(encode(latest_.values_at(t0_ + milliseconds(34)), WordOrder::kHighFirst)[kStatus],
            kCameraOk | kPipelineError);
}

// A lost camera: frames still come (the cameras' status), without measurements; the PLC
// sees camera_ok and valid clear, and no pipeline error, from the first such frame.
TEST_F(LatestMeasurementTest, ALostCameraClearsCameraOkAndValid) {
  latest_.update(1, measured(500.0, true), t0_, milliseconds(0));
  latest_.update_cameras(false);
  latest_.update_missing(t0_ + milliseconds(33));
  EXPECT_EQ(encode(latest_.values_at(t0_ + milliseconds(34)), WordOrder::kHighFirst)[kStatus], 0);
  latest_.update_cameras(true);
  latest_.update(2, measured(501.0, true), t0_ + milliseconds(66), milliseconds(0));
  EXPECT_EQ(encode(latest_.values_at(t0_ + milliseconds(67)), WordOrder::kHighFirst)[kStatus],
            kValid | kCameraOk);
}

TEST_F(LatestMeasurementTest, TheCauseOfTheNewestMeasurementIsShown) {
  latest_.update(3, measured(0.0, false, InvalidCause::kTooLittleSoil), t0_, milliseconds(0));
  EXPECT_EQ(encode(latest_.values_at(t0_), WordOrder::kHighFirst)[kStatus],
            kCameraOk | kTooLittleSoil);
  latest_.update(4, measured(1448.81, false, InvalidCause::kOutOfRange), t0_, milliseconds(0));
  EXPECT_EQ(encode(latest_.values_at(t0_), WordOrder::kHighFirst)[kStatus],
            kCameraOk | kImplausible);
  latest_.update(5, measured(518.0, true), t0_, milliseconds(0));
  EXPECT_EQ(latest_.values_at(t0_).cause, InvalidCause::kNone);
}

// estimation.temporal's held distance: valid with the held bit, and as old as the frame
// it was measured in, not as the frame that carried it.
TEST_F(LatestMeasurementTest, AHeldDistanceSetsHeldAndCountsItsAgeFromItsOwnFrame) {
  GroundDistance held = measured(518.25, true);
  held.held = true;
  held.held_ms = 66.7;
  latest_.update(9, held, t0_, milliseconds(12));
  const RegisterBlock block =
      encode(latest_.values_at(t0_ + milliseconds(5)), WordOrder::kHighFirst);
  EXPECT_EQ(block[kStatus], kValid | kCameraOk | kHeld);
  EXPECT_EQ(block[kStatus], 0x0083);
  EXPECT_EQ(block[kAgeMs], 12 + 66 + 5);  // capture to arrival, held, arrival to now
  EXPECT_EQ(block[kDistanceHundredthsMm + 1], 51825);

  latest_.update(10, measured(518.5, true), t0_ + milliseconds(33), milliseconds(12));
  EXPECT_EQ(encode(latest_.values_at(t0_ + milliseconds(33)), WordOrder::kHighFirst)[kStatus],
            kValid | kCameraOk);
  // Held but gone stale: neither valid nor held.
  latest_.update(11, held, t0_ + milliseconds(40), milliseconds(0));
  EXPECT_EQ(encode(latest_.values_at(t0_ + milliseconds(400)), WordOrder::kHighFirst)[kStatus],
            kStale);
}

}  // namespace
}  // namespace tilth::modbus
