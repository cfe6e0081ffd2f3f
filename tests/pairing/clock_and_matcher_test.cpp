// The parts of pairing on their own: a camera clock put on the host's despite jitter and
// drift, and the matchers' count of frames left without a partner.
#include <gtest/gtest.h>

#include "camera_pair_model.h"
#include "capture_clock.h"
#include "order_matcher.h"
#include "time_matcher.h"

namespace tilth::pairing {
namespace {

constexpr std::int64_t kMs = 1'000'000;

// Transfer 4 ms + jitter in [0, 3 ms), drift 80 ppm, 2 s window: once the window holds
// a few dozen frames the estimate is the capture time plus the 4 ms least latency, off
// by the jitter floor (~3 ms / 60 frames) plus drift over the window (80 ppm x 2 s =
// 0.16 ms), so well within 0.5 ms.
TEST(CaptureClock, FindsTheCaptureTimeUnderJitterAndDrift) {
  testing::CameraModel camera{
      .epoch_ns = 77'000 * kMs, .drift_ppm = 80, .latency_ns = 4 * kMs, .jitter_ns = 3 * kMs};
  CaptureClock clock(2'000 * kMs);
  double worst = 0;
  for (const auto& shot : testing::shoot(camera, camera, 900)) {
    if (shot.side != kDepth) continue;
    const std::int64_t estimate = clock.capture_ns(shot.device_ns, shot.host_ns);
    if (shot.index < 60) continue;
    worst = std::max(worst, std::abs(static_cast<double>(estimate - shot.capture_ns - 4 * kMs)));
  }
  EXPECT_LT(worst, 0.5 * kMs);
}

TEST(CaptureClock, WithoutDeviceTimestampsTheHostTimeIsUsed) {
  CaptureClock clock(2'000 * kMs);
  EXPECT_EQ(clock.capture_ns(0, 123'456), 123'456);
}

PendingFrame at(std::int64_t capture_ms, std::uint64_t id = 0) {
  PendingFrame frame;
  frame.capture_ns = capture_ms * kMs;
  frame.info.frame_id = id;
  return frame;
}

TEST(TimeMatcher, CountsWhatFindsNoPartnerAndPrefersTheCloserFrame) {
  TimeMatcher matcher(8 * kMs, 100 * kMs);
  EXPECT_TRUE(matcher.add(kDepth, at(0)).empty());
  EXPECT_TRUE(matcher.add(kDepth, at(10)).empty());
  // 12 is within 8 ms of both 10 and... only 10 (0 is 12 away): 0 is dropped.
  auto pairs = matcher.add(kColor, at(12));
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].depth.capture_ns, 10 * kMs);
  EXPECT_EQ(matcher.unmatched(kDepth), 1u);
  // A colour frame alone is kept until max_wait has passed on the newest capture.
  EXPECT_TRUE(matcher.add(kColor, at(50)).empty());
  EXPECT_TRUE(matcher.add(kColor, at(140)).empty());
  EXPECT_EQ(matcher.unmatched(kColor), 0u);
  EXPECT_TRUE(matcher.add(kColor, at(151)).empty());
  EXPECT_EQ(matcher.unmatched(kColor), 1u);  // 50 waited 101 ms
  matcher.clear();
  EXPECT_EQ(matcher.unmatched(kColor), 3u);
}

TEST(OrderMatcher, PairsByIdDifferenceAndDropsFramesWhosePartnerWasLost) {
  OrderMatcher matcher(2 * kMs, 500 * kMs);
  EXPECT_TRUE(matcher.add(kDepth, at(0, 7)).empty());
  auto pairs = matcher.add(kColor, at(1, 107));  // difference 100
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_TRUE(matcher.add(kDepth, at(33, 8)).empty());
  EXPECT_TRUE(matcher.add(kDepth, at(66, 9)).empty());
  pairs = matcher.add(kColor, at(67, 109));  // 108 was lost: depth 8 has no partner
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].depth.info.frame_id, 9u);
  EXPECT_EQ(matcher.unmatched(kDepth), 1u);
  // Ids that pair but captures that do not: the order slipped; re-found from times.
  EXPECT_TRUE(matcher.add(kDepth, at(100, 10)).empty());
  pairs = matcher.add(kColor, at(133, 110));
  EXPECT_TRUE(pairs.empty());
  EXPECT_EQ(matcher.unmatched(kDepth), 2u);  // depth 10 had no partner in time
  pairs = matcher.add(kDepth, at(133, 11));  // difference now 99
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].color.info.frame_id, 110u);
}

}  // namespace
}  // namespace tilth::pairing
