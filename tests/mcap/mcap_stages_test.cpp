// mcap.writer -> mcap.player through the real runtime: every pixel, timestamp and truth
// survives in each pixel format and compression; what the file holds (channels,
// schemas, attachments, metadata, summary); seeking by time; every chunk compressed at
// the rig's full image sizes when the writer is told to wait.

#include <chrono>
#include <fstream>

#include "mcap_fixture.h"
#include "mcap_reader.h"
#include "mcap_recording.h"
#include "raw_image.h"

namespace tilth::testing {
namespace {

using nlohmann::json;

class McapStagesTest : public McapTest {};

TEST_F(McapStagesTest, RoundTripKeepsEveryPixelTimestampAndTruth) {
  frames_ = make_frames(5, small_calibration(), 3);
  const fs::path file = dir_.path() / "bgr.mcap";
  const RunResult recorded = record(file, PixelFormat::kBgr8);
  ASSERT_FALSE(recorded.failed) << recorded.failure;
  const RunResult played = play(file);
  ASSERT_FALSE(played.failed) << played.failure;
  expect_played(PixelFormat::kBgr8, 0, frames_.size());
  EXPECT_TRUE(warnings().empty());
}

TEST_F(McapStagesTest, RoundTripOfBayerAtFullSizeInEveryCompression) {
  const json calibration = json::parse(read_text(shipped_calibration_file()));
  frames_ = make_frames(2, calibration, 1);
  for (const std::string compression : {"zstd", "lz4", "none"}) {
    SCOPED_TRACE(compression);
    const fs::path file = dir_.path() / (compression + ".mcap");
    const RunResult recorded =
        record(file, PixelFormat::kBayerGrbg8,
               {{"compression", compression}, {"calibration", shipped_calibration_file()}});
    ASSERT_FALSE(recorded.failed) << recorded.failure;
    const RunResult played = play(file);
    ASSERT_FALSE(played.failed) << played.failure;
    expect_played(PixelFormat::kBayerGrbg8, 0, frames_.size());
    mcap::McapReader reader(file);
    ASSERT_FALSE(reader.chunks().empty());
    EXPECT_EQ(reader.chunks().front().compression, compression == "none" ? "" : compression);
  }
}

TEST_F(McapStagesTest, FileHoldsChannelsSchemasCalibrationAndSummary) {
  frames_ = make_frames(4, small_calibration(), 3);
  const fs::path graph_file = dir_.write("recorded.graph.json", R"({"nodes": {}})");
  const fs::path file = dir_.path() / "contents.mcap";
  const RunResult recorded =
      record(file, PixelFormat::kBgr8, {{"graph_file", graph_file}, {"chunk_size", 1}});
  ASSERT_FALSE(recorded.failed) << recorded.failure;

  mcap::McapReader reader(file);
  EXPECT_FALSE(reader.recovery());
  ASSERT_TRUE(reader.statistics());
  std::map<std::string, std::uint64_t> counts;
  for (const auto& [id, channel] : reader.channels()) {
    const mcap::Schema& schema = reader.schemas().at(channel.schema_id);
    if (channel.topic == "/truth") {
      EXPECT_EQ(channel.message_encoding, "json");
      EXPECT_EQ(schema.encoding, "jsonschema");
      EXPECT_EQ(schema.name, "tilth.GroundTruth");
    } else {
      EXPECT_EQ(channel.message_encoding, "cdr");
      EXPECT_EQ(schema.encoding, "ros2msg");
      EXPECT_EQ(schema.name, "foxglove_msgs/msg/RawImage");
    }
    counts[channel.topic] = reader.statistics()->channel_message_counts.at(id);
  }
  // Frames without truth (every second one) have no /truth message.
  const std::map<std::string, std::uint64_t> expected_counts{
      {"/tof/raw", 4}, {"/color/image", 4}, {"/truth", 2}, {"/truth/mask", 2}};
  EXPECT_EQ(counts, expected_counts);
  EXPECT_EQ(reader.chunks().size(), 4u);  // chunk_size 1: one frame per chunk
  EXPECT_EQ(reader.statistics()->message_start_time, 1'000'000'000u);
  EXPECT_EQ(reader.statistics()->message_end_time, 1'300'400'000u);

  EXPECT_EQ(reader.find_attachment("rig.calib.json")->data, read_text(calibration_file_));
  EXPECT_EQ(reader.find_attachment("recorded.graph.json")->data, read_text(graph_file));
  ASSERT_EQ(reader.metadata().size(), 2u);
  EXPECT_EQ(reader.read_metadata(reader.metadata()[0]).values.at("json"),
            read_text(calibration_file_));

  // The first colour message: a RawImage in CDR, byte by byte where it is not pixels.
  const std::vector<mcap::Message> messages = reader.read_chunk(reader.chunks().front());
  ASSERT_EQ(messages.size(), 4u);  // raw, color, truth, mask
  const std::string& cdr = messages[1].data;
  const std::string head(
      "\x00\x01\x00\x00"                  // CDR, little-endian
      "\x01\x00\x00\x00\x80\x1a\x06\x00"  // timestamp 1 s 400000 ns
      "\x06\x00\x00\x00"
      "color\x00"                         // frame_id, NUL-terminated
      "\x00\x00"                          // aligned to 4
      "\x28\x00\x00\x00\x1e\x00\x00\x00"  // width 40, height 30
      "\x05\x00\x00\x00"
      "bgr8\x00"
      "\x00\x00\x00"
      "\x78\x00\x00\x00"   // step 120
      "\x10\x0e\x00\x00",  // 3600 data bytes
      52);
  ASSERT_EQ(cdr.size(), head.size() + 3600);
  EXPECT_EQ(cdr.substr(0, head.size()), head);
  EXPECT_EQ(cdr.substr(head.size()),
            std::string(reinterpret_cast<const char*>(frames_[0].color.data), 3600));
  EXPECT_EQ(messages[1].sequence, 3u);
  EXPECT_EQ(messages[1].log_time, 1'000'400'000u);
  EXPECT_EQ(messages[1].publish_time, 1'000'400'000u);
  const mcap::RawImage color = mcap::decode_raw_image(cdr, "test");
  EXPECT_EQ(color.encoding, "bgr8");
  EXPECT_EQ(color.frame_id, "color");
  EXPECT_EQ(color.timestamp_ns, 1'000'400'000);
  EXPECT_TRUE(same_pixels(frames_[0].color, color.pixels));
  EXPECT_EQ(json::parse(messages[2].data)["distance_mm"], 500.0);

  const mcap::RecordingInfo info = mcap::recording_info(file);
  EXPECT_TRUE(info.has_summary);
  EXPECT_EQ(info.message_count, 12u);
  EXPECT_EQ(info.chunk_count, 4u);
  EXPECT_DOUBLE_EQ(info.duration_s(), 0.3004);
  EXPECT_NE(
      mcap::format_info(info).find("/truth/mask  2 messages  foxglove_msgs/msg/RawImage (cdr)"),
      std::string::npos)
      << mcap::format_info(info);
}

TEST_F(McapStagesTest, SeeksByTimeWithoutReadingTheChunksBefore) {
  frames_ = make_frames(10, small_calibration(), 3);
  const fs::path file = dir_.path() / "seek.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8, {{"chunk_size", 1}}).failed);
  // Damage the first chunk: a player that reads it fails.
  mcap::McapReader reader(file);
  const mcap::ChunkIndex first = reader.chunks().front();
  {
    std::fstream bytes(file, std::ios::in | std::ios::out | std::ios::binary);
    bytes.seekp(static_cast<std::streamoff>(first.chunk_start_offset + first.chunk_length - 10));
    bytes.put('\x55');
  }
  const RunResult played = play(file, {{"start_s", 0.25}, {"end_s", 0.65}});
  ASSERT_FALSE(played.failed) << played.failure;
  expect_played(PixelFormat::kBgr8, 3, 4);  // depth times 0.3 .. 0.6 s after the first
  EXPECT_TRUE(play(file).failed);
}

TEST_F(McapStagesTest, PacesAtTheRecordedRate) {
  frames_ = make_frames(4, small_calibration(), 3, 50'000'000);
  const fs::path file = dir_.path() / "paced.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8).failed);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_FALSE(play(file, {{"rate", 1.0}}).failed);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(seconds, 0.15);
  EXPECT_EQ(captured_.size(), 4u);
}

// 640x480 mono16 + 1280x1024 bgr8 with sensor noise, as the rig delivers them: with
// when_behind: wait every chunk is compressed, however far compression falls behind.
// (Speed is measured by bench/mcap, not here.)
TEST_F(McapStagesTest, WaitingWriterCompressesEveryChunk) {
  const json calibration = json::parse(read_text(shipped_calibration_file()));
  const int count = 45;
  frames_ = make_frames(count, calibration, 3);
  cv::RNG random(7);
  for (TestFrame& frame : frames_) {
    cv::Mat depth(frame.depth.size(), CV_32F);
    random.fill(depth, cv::RNG::NORMAL, 20000, 40);
    depth.convertTo(frame.depth, CV_16U);
    cv::Mat color(frame.color.size(), CV_32FC3);
    random.fill(color, cv::RNG::NORMAL, 110, 3);
    color.convertTo(frame.color, CV_8UC3);
  }
  const fs::path file = dir_.path() / "throughput.mcap";
  const RunResult recorded =
      record(file, PixelFormat::kBgr8,
             {{"calibration", shipped_calibration_file()}, {"when_behind", "wait"}});
  ASSERT_FALSE(recorded.failed) << recorded.failure;
  EXPECT_EQ(mcap::recording_info(file).compressions,
            (std::vector<std::pair<std::string, std::uint64_t>>{{"zstd", count}}));
}

}  // namespace
}  // namespace tilth::testing
