#include "mcap_fixture.h"

namespace tilth::testing {
namespace {

using nlohmann::json;

json edge(const std::string& from, const std::string& to) { return json::array({from, to}); }

}  // namespace

McapTest::McapTest() {
  registry_.load(TILTH_MCAP_PLUGIN);
  write_text(calibration_file_, small_calibration().dump(2));
}

RunResult McapTest::record(const fs::path& file, PixelFormat format, json writer_params) {
  feed_.clear();
  for (const TestFrame& frame : frames_) {
    Feed feed;
    feed.frame_id = frame.index;
    feed.host_timestamp_ns = frame.host_timestamp_ns;
    feed.raw.gray = frame.depth;
    feed.raw.device_timestamp_ns = frame.depth_timestamp_ns;
    feed.color.pixels = frame.color;
    feed.color.format = format;
    feed.color.device_timestamp_ns = frame.color_timestamp_ns;
    feed.color.sensor_offset = color_sensor_offset_;
    GroundTruth truth;
    truth.distance_mm = frame.ground_truth_mm;
    truth.residue_mask = frame.mask;
    feed.truth = truth;
    feed_.push_back(std::move(feed));
  }
  writer_params["path"] = file.string();
  if (!writer_params.contains("calibration")) writer_params["calibration"] = calibration_file_;
  const json graph = {{"nodes",
                       {{"in", {{"type", "test.feed"}}},
                        {"w", {{"type", "mcap.writer"}, {"params", writer_params}}}}},
                      {"edges", json::array({edge("in.raw", "w.raw"), edge("in.color", "w.color"),
                                             edge("in.truth", "w.truth")})}};
  return run(graph.dump());
}

std::string McapTest::player_graph(const fs::path& file, json player_params) {
  player_params["path"] = file.string();
  const json graph = {
      {"nodes",
       {{"src", {{"type", "mcap.player"}, {"params", player_params}}},
        {"out", {{"type", "test.capture"}}}}},
      {"edges", json::array({edge("src.raw", "out.raw"), edge("src.color", "out.color"),
                             edge("src.truth", "out.truth")})}};
  return graph.dump();
}

RunResult McapTest::play(const fs::path& file, json player_params) {
  captured_.clear();
  return run(player_graph(file, std::move(player_params)));
}

void McapTest::expect_played(PixelFormat format, std::size_t first, std::size_t count) {
  ASSERT_EQ(captured_.size(), count);
  for (std::size_t i = 0; i < count; ++i) {
    SCOPED_TRACE("frame " + std::to_string(first + i));
    const TestFrame& expected = frames_[first + i];
    const Captured& got = captured_[i];
    EXPECT_EQ(got.info.frame_id, expected.index);
    EXPECT_EQ(got.info.device_timestamp_ns, expected.depth_timestamp_ns);
    EXPECT_EQ(got.info.host_timestamp_ns, expected.host_timestamp_ns);
    EXPECT_TRUE(same_pixels(expected.depth, got.raw->gray));
    EXPECT_EQ(got.raw->device_timestamp_ns, expected.depth_timestamp_ns);
    EXPECT_TRUE(same_pixels(expected.color, got.color->pixels));
    EXPECT_EQ(got.color->format, format);
    EXPECT_EQ(got.color->device_timestamp_ns, expected.color_timestamp_ns);
    ASSERT_TRUE(got.truth);
    EXPECT_EQ(got.truth->distance_mm, expected.ground_truth_mm);
    if (expected.mask.empty()) {
      EXPECT_TRUE(got.truth->residue_mask.empty());
    } else {
      EXPECT_TRUE(same_pixels(expected.mask, got.truth->residue_mask));
    }
  }
}

}  // namespace tilth::testing
