// The host clock's trigger grid (software_trigger.h): the instants every camera at one rate
// is fired at. Firing real cameras is tested against the simulator in
// test_software_trigger.py.
#include "aravis/software_trigger.h"

#include <gtest/gtest.h>

namespace tilth::aravis {
namespace {

using std::chrono::nanoseconds;
using TimePoint = std::chrono::steady_clock::time_point;

TimePoint at(std::int64_t ns) { return TimePoint(nanoseconds(ns)); }

TEST(TriggerGrid, PeriodIsTheRateInWholeNanoseconds) {
  EXPECT_EQ(grid_period(30.0), nanoseconds(33'333'333));
  EXPECT_EQ(grid_period(20.0), nanoseconds(50'000'000));
  EXPECT_EQ(grid_period(3.0), nanoseconds(333'333'333));
}

TEST(TriggerGrid, NextInstantIsTheFirstMultipleOfThePeriodFromNow) {
  const nanoseconds period(50'000'000);
  EXPECT_EQ(next_grid_instant(at(1'000'000'000), period), at(1'000'000'000));
  EXPECT_EQ(next_grid_instant(at(1'000'000'001), period), at(1'050'000'000));
  EXPECT_EQ(next_grid_instant(at(1'049'999'999), period), at(1'050'000'000));
}

TEST(TriggerGrid, TwoCamerasAskingAtDifferentTimesGetTheSameInstants) {
  const nanoseconds period = grid_period(30.0);
  const TimePoint first = next_grid_instant(at(7'000'000'123), period);
  const TimePoint second = next_grid_instant(at(7'020'000'000), period);
  EXPECT_EQ(first, second);
  EXPECT_EQ(first.time_since_epoch() % period, nanoseconds(0));
  EXPECT_EQ(next_grid_instant(first + nanoseconds(1), period), first + period);
}

}  // namespace
}  // namespace tilth::aravis
