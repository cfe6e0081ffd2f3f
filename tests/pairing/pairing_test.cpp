// pairing.depth_color, loaded from the built plugin as the runtime loads it, on two
// simulated cameras (camera_pair_model.h): clock offsets, drift, jitter and dropped
// frames on either side; every pair it emits must hold frames of the same capture.
#include <deque>
#include <map>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "camera_pair_model.h"
#include "framework/stage_registry.h"
#include "tilth/messages/camera_status.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/stage_params.h"

namespace tilth::pairing {
namespace {

using testing::CameraModel;
using testing::Shot;

constexpr std::int64_t kMs = 1'000'000;

class Collected final : public Synchronizer::Output {
 public:
  Frame& emit() override {
    outputs_.emplace_back(3);
    frames_.emplace_back(FrameInfo{}, std::span<const Packet>{}, outputs_.back());
    return frames_.back();
  }
  std::size_t size() const { return frames_.size(); }
  const FrameInfo& info(std::size_t i) const { return frames_[i].info(); }
  const Packet& output(std::size_t i, std::size_t port) const { return outputs_[i][port]; }

 private:
  std::deque<std::vector<Packet>> outputs_;
  std::deque<Frame> frames_;
};

class PairingTest : public ::testing::Test {
 protected:
  void make(const nlohmann::json& params) {
    registry_.load(TILTH_PAIRING_PLUGIN);
    instance_ =
        registry_.create("pairing.depth_color",
                         {"pair",
                          stage_params(registry_.find("pairing.depth_color")->descriptor, params),
                          Logger("pair"),
                          {}});
    stage_ = dynamic_cast<Synchronizer*>(instance_.stage.get());
    ASSERT_NE(stage_, nullptr);
  }

  // One camera frame (or, without an image, a status saying the camera is lost).
  void deliver(const Shot& shot, bool with_image = true) {
    FrameInfo info;
    info.frame_id = shot.block_id;
    info.device_timestamp_ns = shot.device_ns;
    info.host_timestamp_ns = shot.host_ns;
    std::vector<Packet> inputs(4);
    auto status = std::make_shared<CameraStatus>();
    status->streaming = with_image;
    status->problem = with_image ? "" : "no frame for 70 ms";
    const std::size_t first = shot.side == kDepth ? 0 : 2;
    inputs[first + 1] = Packet(info, status);
    if (with_image && shot.side == kDepth) {
      auto raw = std::make_shared<RawTofFrame>();
      raw->device_timestamp_ns = shot.device_ns;
      inputs[0] = Packet(info, raw);
      depth_index_[shot.device_ns] = shot.index;
    } else if (with_image) {
      auto color = std::make_shared<ColorImage>();
      color->device_timestamp_ns = shot.device_ns;
      inputs[2] = Packet(info, color);
      color_index_[shot.device_ns] = shot.index;
    }
    stage_->accept(Frame(info, inputs, {}), out_);
  }

  // Capture indices of each emitted pair (depth, colour).
  std::vector<std::pair<std::uint64_t, std::uint64_t>> pairs() const {
    std::vector<std::pair<std::uint64_t, std::uint64_t>> result;
    for (std::size_t i = 0; i < out_.size(); ++i) {
      if (out_.output(i, 0).empty()) continue;
      result.emplace_back(depth_index_.at(out_.output(i, 0).get<RawTofFrame>().device_timestamp_ns),
                          color_index_.at(out_.output(i, 1).get<ColorImage>().device_timestamp_ns));
    }
    return result;
  }

  StageRegistry registry_;
  StageInstance instance_;
  Synchronizer* stage_ = nullptr;
  Collected out_;
  std::map<std::int64_t, std::uint64_t> depth_index_;
  std::map<std::int64_t, std::uint64_t> color_index_;
};

// Free-running 30 fps cameras 20 s long: clocks 3 s and 9000 s off the host's and
// drifting +60 / -40 ppm, the colour camera's rate 100 ppm off (its phase slides from
// 2 to 4 ms), transfer 4 and 9 ms plus up to 3 ms jitter; the 5 ms transfer difference
// is the color_delay_ms setting.
CameraModel free_depth() {
  return {.epoch_ns = 3'000 * kMs, .drift_ppm = 60, .latency_ns = 4 * kMs, .jitter_ns = 3 * kMs};
}
CameraModel free_color() {
  return {.period_ns = 33'336'666,
          .phase_ns = 2 * kMs,
          .epoch_ns = 9'000'000 * kMs,
          .drift_ppm = -40,
          .latency_ns = 9 * kMs,
          .jitter_ns = 3 * kMs,
          .first_id = 500};
}

TEST_F(PairingTest, FreeRunningCamerasPairFrameForFrameDespiteOffsetDriftAndJitter) {
  make({{"tolerance_ms", 8.0}, {"color_delay_ms", 5.0}});
  for (const Shot& shot : testing::shoot(free_depth(), free_color(), 600)) deliver(shot);
  const auto paired = pairs();
  ASSERT_EQ(paired.size(), 600u);
  for (const auto& [depth, color] : paired) ASSERT_EQ(depth, color);
  // The pair is the depth frame's: its id and times.
  EXPECT_EQ(out_.info(0).frame_id, 1u);
  EXPECT_EQ(out_.info(599).frame_id, 600u);
  EXPECT_TRUE(out_.output(599, 2).get<CameraStatus>().streaming);
  EXPECT_EQ(out_.output(599, 2).get<CameraStatus>().completed, 600u);
}

TEST_F(PairingTest, DroppedFramesOnEitherSideLeaveTheirPartnersUnpaired) {
  make({{"tolerance_ms", 8.0}, {"color_delay_ms", 5.0}});
  CameraModel depth = free_depth();
  CameraModel color = free_color();
  depth.dropped = {0, 10, 11, 50, 300};
  color.dropped = {20, 70, 71, 72, 599};
  for (const Shot& shot : testing::shoot(depth, color, 600)) deliver(shot);
  const auto paired = pairs();
  EXPECT_EQ(paired.size(), 590u);
  for (const auto& [d, c] : paired) ASSERT_EQ(d, c);
}

// Half a frame period apart, no two frames are within the tolerance: nothing pairs,
// rather than anything pairing wrongly.
TEST_F(PairingTest, CamerasFurtherApartThanTheToleranceNeverPair) {
  make({{"tolerance_ms", 8.0}});
  CameraModel color = free_color();
  color.latency_ns = free_depth().latency_ns;
  color.phase_ns = 16 * kMs;
  color.period_ns = free_depth().period_ns;
  for (const Shot& shot : testing::shoot(free_depth(), color, 300)) deliver(shot);
  EXPECT_EQ(pairs().size(), 0u);
}

// Triggered cameras: ids 1.. and 500.., the same capture instant, frames lost on either
// side, then the colour camera restarts (ids and clock from zero): pairing finds the new
// id difference and carries on.
TEST_F(PairingTest, TriggeredCamerasPairByTriggerOrderAcrossLossesAndARestart) {
  make({{"mode", "triggered"}, {"tolerance_ms", 4.0}, {"color_delay_ms", 5.0}});
  CameraModel depth = free_depth();
  CameraModel color = free_color();
  color.phase_ns = 0;
  color.period_ns = depth.period_ns;
  depth.dropped = {3, 4, 40};
  color.dropped = {0, 41, 42};
  for (const Shot& shot : testing::shoot(depth, color, 100)) deliver(shot);
  EXPECT_EQ(pairs().size(), 94u);

  CameraModel restarted = color;
  restarted.first_id = 0;
  restarted.epoch_ns = -3'300 * kMs;  // its clock reads 0 at host time 3.3 s
  restarted.dropped = {};
  auto later = testing::shoot(depth, restarted, 200);
  std::erase_if(later, [](const Shot& shot) { return shot.index < 101; });
  for (const Shot& shot : later) deliver(shot);
  const auto paired = pairs();
  for (const auto& [d, c] : paired) ASSERT_EQ(d, c);
  // All 99 shots from 101 on pair: the first frames after the restart fix the new id
  // difference by capture time and pair at once.
  EXPECT_EQ(paired.size(), 94u + 99u);
}

// A lost camera's status frames come out at once as frames without images, saying so;
// pairing resumes when the camera is back.
TEST_F(PairingTest, ALostCameraTurnsEveryFrameImagelessUntilItReturns) {
  make({});
  const auto shots = testing::shoot(free_depth(), free_color(), 60);
  for (const Shot& shot : shots) {
    if (shot.index < 20) deliver(shot);
  }
  const std::size_t before = out_.size();
  for (const Shot& shot : shots) {
    if (shot.index >= 20 && shot.index < 40 && shot.side == kColor) deliver(shot, false);
  }
  ASSERT_EQ(out_.size(), before + 20);
  for (std::size_t i = before; i < out_.size(); ++i) {
    EXPECT_TRUE(out_.output(i, 0).empty());
    const auto& status = out_.output(i, 2).get<CameraStatus>();
    EXPECT_FALSE(status.streaming);
    EXPECT_EQ(status.problem, "colour: no frame for 70 ms");
  }
  for (const Shot& shot : shots) {
    if (shot.index >= 40) deliver(shot);
  }
  EXPECT_EQ(pairs().size(), 40u);
  EXPECT_TRUE(out_.output(out_.size() - 1, 2).get<CameraStatus>().streaming);
}

}  // namespace
}  // namespace tilth::pairing
