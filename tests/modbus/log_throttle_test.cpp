// Flood-proof logging: the first event of a period is logged at once, the rest of the
// period in one summary line when it ends.
#include "log_throttle.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace tilth::modbus {
namespace {

using std::chrono::milliseconds;

class LogThrottleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    previous_ =
        set_log_handler([this](LogLevel level, std::string_view where, std::string_view message) {
          lines_.push_back(std::string(to_string(level)) + " " + std::string(where) + ": " +
                           std::string(message));
        });
  }
  void TearDown() override { set_log_handler(previous_); }

  std::vector<std::string> lines_;
  LogHandler previous_;
  const LogThrottle::Clock::time_point t0_{};
};

TEST_F(LogThrottleTest, OneLineAtOnceThenOneSummaryPerPeriod) {
  LogThrottle throttle(Logger("plc"), LogLevel::kWarning, milliseconds(10000));
  EXPECT_FALSE(throttle.deadline());
  throttle.event(t0_, "refused 1");
  ASSERT_EQ(lines_.size(), 1u);
  EXPECT_FALSE(throttle.deadline());  // nothing held back
  for (int i = 2; i <= 50; ++i)
    throttle.event(t0_ + milliseconds(i * 100), "refused " + std::to_string(i));
  EXPECT_EQ(lines_.size(), 1u);
  EXPECT_EQ(throttle.deadline(), t0_ + milliseconds(10000));
  throttle.flush(t0_ + milliseconds(9999));
  EXPECT_EQ(lines_.size(), 1u);
  throttle.flush(t0_ + milliseconds(10000));
  ASSERT_EQ(lines_.size(), 2u);
  EXPECT_FALSE(throttle.deadline());
  // The summary starts a period of its own: the next event is held back again.
  throttle.event(t0_ + milliseconds(12000), "refused 51");
  EXPECT_EQ(lines_.size(), 2u);
  throttle.flush(t0_ + milliseconds(20000));
  // A quiet period later, an event is logged as it happens.
  throttle.event(t0_ + milliseconds(40000), "refused 52");
  EXPECT_EQ(lines_, (std::vector<std::string>{
                        "warning plc: refused 1",
                        "warning plc: 49 more like it in the last 10 s; the latest: refused 50",
                        "warning plc: 1 more like it in the last 10 s; the latest: refused 51",
                        "warning plc: refused 52"}));
}

TEST_F(LogThrottleTest, AnEventAfterTheDeadlineFirstFlushesTheSummary) {
  LogThrottle throttle(Logger("plc"), LogLevel::kInfo, milliseconds(10000));
  throttle.event(t0_, "a");
  throttle.event(t0_ + milliseconds(1), "b");
  throttle.event(t0_ + milliseconds(10001), "c");  // no flush() in between
  EXPECT_EQ(lines_,
            (std::vector<std::string>{"info plc: a",
                                      "info plc: 1 more like it in the last 10 s; the latest: b"}));
  EXPECT_EQ(throttle.deadline(), t0_ + milliseconds(20001));
}

TEST_F(LogThrottleTest, SummarizeLogsWhatIsHeldBackBeforeThePeriodEnds) {
  LogThrottle throttle(Logger("plc"), LogLevel::kInfo, milliseconds(10000));
  throttle.summarize(t0_);  // nothing held back: nothing to say
  throttle.event(t0_, "a");
  throttle.event(t0_ + milliseconds(1000), "b");
  throttle.event(t0_ + milliseconds(2000), "c");
  throttle.summarize(t0_ + milliseconds(3500));
  EXPECT_EQ(lines_, (std::vector<std::string>{
                        "info plc: a", "info plc: 2 more like it in the last 3 s; the latest: c"}));
  EXPECT_FALSE(throttle.deadline());
}

}  // namespace
}  // namespace tilth::modbus
