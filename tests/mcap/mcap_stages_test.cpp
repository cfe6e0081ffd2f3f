// mcap.writer -> mcap.player through the real runtime: every pixel, timestamp (device
// and host, with host_time: recorded) and truth survives in each pixel format and
// compression; by default frames get host times when played; what the file holds
// (channels, schemas, attachments, metadata, summary); log times are host capture times
// and image stamps device times, or device times in both (log_time: device, and older
// recordings); seeking by log time, pacing by device time, playing chunks in the order
// written; every chunk compressed at the rig's full image sizes when the writer is told
// to wait.

#include <algorithm>
#include <chrono>
#include <fstream>

#include "mcap/mcap_reader.h"
#include "mcap/mcap_recording.h"
#include "mcap/raw_image.h"
#include "mcap_fixture.h"
#include "tilth/calibration.h"
#include "tilth/messages/camera_status.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/version.h"

namespace tilth::testing {
namespace {

using nlohmann::json;

class McapStagesTest : public McapTest {
 protected:
  // Every message of the file, in the order written, with its channel's topic.
  static std::vector<std::pair<std::string, mcap::Message>> messages_of(const fs::path& file) {
    mcap::McapReader reader(file);
    std::vector<std::pair<std::string, mcap::Message>> messages;
    for (const mcap::ChunkIndex& chunk : reader.chunks()) {
      for (mcap::Message& message : reader.read_chunk(chunk)) {
        messages.emplace_back(reader.channels().at(message.channel_id).topic, std::move(message));
      }
    }
    return messages;
  }

  // The image timestamp of a RawImage message, or the `timestamp` of a JSON message.
  static std::int64_t stamp_of(const std::string& topic, const mcap::Message& message) {
    if (message.data.starts_with("{")) {
      const json stamp = json::parse(message.data)["timestamp"];
      return stamp["sec"].get<std::int64_t>() * 1'000'000'000 + stamp["nsec"].get<std::int64_t>();
    }
    return mcap::decode_raw_image(message.data, topic).timestamp_ns;
  }

  // An mcap.writer that a test hands frames to itself, one chunk per frame.
  StageInstance direct_writer(const fs::path& file) {
    StageContext context{"w",
                         Params(json{{"path", file.string()},
                                     {"compression", "zstd"},
                                     {"when_behind", "wait"},
                                     {"log_time", "host"},
                                     {"chunk_size", 1},
                                     {"calibration", calibration_file_.string()},
                                     {"graph_file", ""}}),
                         Logger("w"),
                         {}};
    return registry_.create("mcap.writer", context);
  }

  // Null when no frame has the id.
  const TestFrame* frame_with_id(std::uint64_t id) const {
    const auto found = std::find_if(frames_.begin(), frames_.end(),
                                    [&](const TestFrame& frame) { return frame.index == id; });
    return found == frames_.end() ? nullptr : &*found;
  }
};

TEST_F(McapStagesTest, RoundTripKeepsEveryPixelTimestampAndTruth) {
  frames_ = make_frames(5, small_calibration(), 3);
  const fs::path file = dir_.path() / "bgr.mcap";
  const RunResult recorded = record(file, PixelFormat::kBgr8);
  ASSERT_FALSE(recorded.failed) << recorded.failure;
  const RunResult played = play(file, {{"host_time", "recorded"}});
  ASSERT_FALSE(played.failed) << played.failure;
  expect_played(PixelFormat::kBgr8, 0, frames_.size());
  EXPECT_TRUE(warnings().empty());
}

// By default, as live: the host clock when each frame is played, not its log time.
TEST_F(McapStagesTest, HostTimesAreWhenPlayedByDefault) {
  frames_ = make_frames(3, small_calibration(), 3);
  const fs::path file = dir_.path() / "replayed.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8).failed);
  for (const json& params : {json::object(), json{{"host_time", "replayed"}}}) {
    SCOPED_TRACE(params.dump());
    const auto before = std::chrono::system_clock::now().time_since_epoch().count();
    const RunResult played = play(file, params);
    const auto after = std::chrono::system_clock::now().time_since_epoch().count();
    ASSERT_FALSE(played.failed) << played.failure;
    ASSERT_EQ(captured_.size(), frames_.size());
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      EXPECT_EQ(captured_[i].info.frame_id, frames_[i].index);
      EXPECT_EQ(captured_[i].info.device_timestamp_ns, frames_[i].depth_timestamp_ns) << i;
      EXPECT_GE(captured_[i].info.host_timestamp_ns, before) << i;
      EXPECT_LE(captured_[i].info.host_timestamp_ns, after) << i;
      EXPECT_NE(captured_[i].info.host_timestamp_ns, frames_[i].host_timestamp_ns) << i;
    }
  }
}

TEST_F(McapStagesTest, AnUnknownHostTimeIsRefusedBeforeTheGraphRuns) {
  frames_ = make_frames(1, small_calibration(), 3);
  const fs::path file = dir_.path() / "refused.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8).failed);
  EXPECT_EQ(start_error(player_graph(file, {{"host_time", "live"}})),
            (dir_.path() / "graph.json").string() +
                ":/nodes/src/params/host_time: parameter 'host_time': expected one of "
                "'replayed', 'recorded', got \"live\"");
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
    const RunResult played = play(file, {{"host_time", "recorded"}});
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
    const std::map<std::string, std::string> json_schemas{
        {"/truth", "tilth.GroundTruth"},
        {"/tof/calibration", "foxglove.CameraCalibration"},
        {"/color/calibration", "foxglove.CameraCalibration"},
        {"/tf", "foxglove.FrameTransform"}};
    if (const auto found = json_schemas.find(channel.topic); found != json_schemas.end()) {
      EXPECT_EQ(channel.message_encoding, "json");
      EXPECT_EQ(schema.encoding, "jsonschema");
      EXPECT_EQ(schema.name, found->second);
    } else {
      EXPECT_EQ(channel.message_encoding, "cdr");
      EXPECT_EQ(schema.encoding, "ros2msg");
      EXPECT_EQ(schema.name, "foxglove_msgs/msg/RawImage");
    }
    counts[channel.topic] = reader.statistics()->channel_message_counts.at(id);
  }
  // Frames without truth (every second one) have no /truth message; the rig is recorded
  // once, with the first frame.
  const std::map<std::string, std::uint64_t> expected_counts{
      {"/tof/raw", 4},         {"/color/image", 4},       {"/truth", 2}, {"/truth/mask", 2},
      {"/tof/calibration", 1}, {"/color/calibration", 1}, {"/tf", 1}};
  EXPECT_EQ(counts, expected_counts);
  EXPECT_EQ(reader.chunks().size(), 4u);  // chunk_size 1: one frame per chunk
  // Log times are host capture times.
  EXPECT_EQ(reader.statistics()->message_start_time, 1'763'800'000'002'000'000u);
  EXPECT_EQ(reader.statistics()->message_end_time, 1'763'800'000'302'000'000u);

  EXPECT_EQ(reader.find_attachment("rig.calib.json")->data, read_text(calibration_file_));
  EXPECT_EQ(reader.find_attachment("recorded.graph.json")->data, read_text(graph_file));
  ASSERT_EQ(reader.metadata().size(), 2u);
  EXPECT_EQ(reader.read_metadata(reader.metadata()[0]).values.at("json"),
            read_text(calibration_file_));
  const std::map<std::string, std::string> recording{{"node", "w"},
                                                     {"graph_file", "recorded.graph.json"},
                                                     {"log_time", "host"},
                                                     {"tilth_version", std::string(version())}};
  EXPECT_EQ(reader.read_metadata(reader.metadata()[1]).values, recording);

  // The first colour message: a RawImage in CDR, byte by byte where it is not pixels.
  const std::vector<mcap::Message> messages = reader.read_chunk(reader.chunks().front());
  ASSERT_EQ(messages.size(), 7u);  // the rig's 3, raw, color, truth, mask
  const std::string& cdr = messages[4].data;
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
  EXPECT_EQ(messages[4].sequence, 3u);
  EXPECT_EQ(messages[4].log_time, 1'763'800'000'002'000'000u);
  EXPECT_EQ(messages[4].publish_time, 1'763'800'000'002'000'000u);
  const mcap::RawImage color = mcap::decode_raw_image(cdr, "test");
  EXPECT_EQ(color.encoding, "bgr8");
  EXPECT_EQ(color.frame_id, "color");
  EXPECT_EQ(color.timestamp_ns, 1'000'400'000);
  EXPECT_TRUE(same_pixels(frames_[0].color, color.pixels));
  EXPECT_EQ(json::parse(messages[5].data)["distance_mm"], 500.0);

  const mcap::RecordingInfo info = mcap::recording_info(file);
  EXPECT_TRUE(info.has_summary);
  EXPECT_EQ(info.message_count, 15u);
  EXPECT_EQ(info.chunk_count, 4u);
  EXPECT_DOUBLE_EQ(info.duration_s(), 0.3);
  EXPECT_NE(
      mcap::format_info(info).find("/truth/mask  2 messages  foxglove_msgs/msg/RawImage (cdr)"),
      std::string::npos)
      << mcap::format_info(info);
}

// A camera reading out a window of its colour sensor: the file holds the window's pixels,
// the rig's calibration as given, the window (metadata tilth.color_window) and, on
// /color/calibration, the window's intrinsics; mcap.player gives each image its place on
// the sensor again. A window off the image's centre records as well.
TEST_F(McapStagesTest, AColourWindowIsRecordedAndPlayedWhereItLies) {
  for (const cv::Rect& window : {cv::Rect(10, 6, 24, 20), cv::Rect(30, 0, 10, 8)}) {
    SCOPED_TRACE(window_text(window));
    frames_ = make_frames(3, small_calibration(), 3);
    for (TestFrame& frame : frames_) frame.color = frame.color(window).clone();
    color_sensor_offset_ = window.tl();
    const fs::path file = dir_.path() / "window.mcap";
    fs::remove(file);
    const RunResult recorded = record(file, PixelFormat::kBgr8);
    ASSERT_FALSE(recorded.failed) << recorded.failure;

    mcap::McapReader reader(file);
    EXPECT_EQ(reader.find_attachment("rig.calib.json")->data, read_text(calibration_file_));
    ASSERT_EQ(reader.metadata().size(), 3u);  // the rig's, the recording's, the window
    const mcap::Metadata stored = reader.read_metadata(reader.metadata()[2]);
    EXPECT_EQ(stored.name, "tilth.color_window");
    const std::map<std::string, std::string> expected{{"x", std::to_string(window.x)},
                                                      {"y", std::to_string(window.y)},
                                                      {"width", std::to_string(window.width)},
                                                      {"height", std::to_string(window.height)}};
    EXPECT_EQ(stored.values, expected);
    const json color_calibration = json::parse(messages_of(file).at(1).second.data);
    EXPECT_EQ(color_calibration["width"], window.width);
    EXPECT_EQ(color_calibration["height"], window.height);
    EXPECT_DOUBLE_EQ(color_calibration["K"][2].get<double>(), 19.5 - window.x);  // cx
    EXPECT_DOUBLE_EQ(color_calibration["K"][5].get<double>(), 14.5 - window.y);  // cy

    ASSERT_FALSE(play(file, {{"host_time", "recorded"}}).failed);
    expect_played(PixelFormat::kBgr8, 0, frames_.size());
    for (const Captured& played : captured_) {
      EXPECT_EQ(played.color->sensor_offset, window.tl());
      ASSERT_NE(played.raw->rig, nullptr);
      EXPECT_EQ(played.raw->rig->color.width, 40);  // the whole image's calibration
    }
  }
}

// The window is in log time, the host capture times, here twice as far apart as the
// device times.
TEST_F(McapStagesTest, SeeksByLogTimeWithoutReadingTheChunksBefore) {
  frames_ = make_frames(10, small_calibration(), 3);
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    frames_[i].host_timestamp_ns =
        1'763'800'000'000'000'000 + static_cast<std::int64_t>(i) * 200'000'000;
  }
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
  const RunResult played =
      play(file, {{"start_s", 0.5}, {"end_s", 1.3}, {"host_time", "recorded"}});
  ASSERT_FALSE(played.failed) << played.failure;
  expect_played(PixelFormat::kBgr8, 3, 4);  // host times 0.6 .. 1.2 s after the first
  EXPECT_TRUE(play(file).failed);
}

// A window that starts after the last frame would play nothing: the user mistyped, and
// is told how long the recording is before the graph runs.
TEST_F(McapStagesTest, AStartPastTheEndIsRefusedBeforeTheGraphRuns) {
  frames_ = make_frames(10, small_calibration(), 3);  // log times 100 ms apart: 0.9 s
  const fs::path file = dir_.path() / "short.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8, {{"chunk_size", 1}}).failed);
  for (const double start_s : {0.95, 1e12}) {
    SCOPED_TRACE(start_s);
    const std::string error = start_error(player_graph(file, {{"start_s", start_s}}));
    EXPECT_NE(
        error.find(file.string() + ": start_s " + (start_s < 1 ? "0.950" : "1000000000000.000") +
                   " s is past the recording's end: it lasts 0.900 s"),
        std::string::npos)
        << error;
  }
  const RunResult last = play(file, {{"start_s", 0.9}, {"host_time", "recorded"}});
  ASSERT_FALSE(last.failed) << last.failure;
  expect_played(PixelFormat::kBgr8, 9, 1);
}

// By the device times, the camera's rhythm: the host times of a recording made faster
// than real time (a simulation) are 1 ms apart.
TEST_F(McapStagesTest, PacesAtTheRecordedRateOfTheDeviceTimes) {
  frames_ = make_frames(4, small_calibration(), 3, 50'000'000);
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    frames_[i].host_timestamp_ns =
        1'763'800'000'000'000'000 + static_cast<std::int64_t>(i) * 1'000'000;
  }
  const fs::path file = dir_.path() / "paced.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8).failed);
  const auto start = std::chrono::steady_clock::now();
  ASSERT_FALSE(play(file, {{"rate", 1.0}}).failed);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_GE(seconds, 0.15);
  EXPECT_EQ(captured_.size(), 4u);
}

TEST_F(McapStagesTest, LogTimesAreHostCaptureTimesAndImageStampsDeviceTimes) {
  frames_ = make_frames(3, small_calibration(), 3);
  const fs::path file = dir_.path() / "times.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8).failed);
  const auto messages = messages_of(file);
  // 3 frames of raw and colour, 2 of truth and mask, the rig's 3 with the first frame
  ASSERT_EQ(messages.size(), 13u);
  for (const auto& [topic, message] : messages) {
    SCOPED_TRACE(topic + " frame " + std::to_string(message.sequence));
    const TestFrame* frame = frame_with_id(message.sequence);
    ASSERT_NE(frame, nullptr);
    EXPECT_EQ(message.log_time, static_cast<std::uint64_t>(frame->host_timestamp_ns));
    EXPECT_EQ(message.publish_time, message.log_time);
    EXPECT_EQ(stamp_of(topic, message),
              topic == "/color/image" ? frame->color_timestamp_ns : frame->depth_timestamp_ns);
  }
}

// log_time: device records as Tilth did before host times were recorded; such files,
// old ones too, play with the depth device time as the frames' recorded host time.
TEST_F(McapStagesTest, DeviceLogTimesPlayAsHostTimes) {
  frames_ = make_frames(3, small_calibration(), 3);
  const fs::path file = dir_.path() / "device.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8, {{"log_time", "device"}}).failed);
  for (const auto& [topic, message] : messages_of(file)) {
    EXPECT_EQ(message.log_time, static_cast<std::uint64_t>(stamp_of(topic, message))) << topic;
  }
  mcap::McapReader reader(file);
  EXPECT_EQ(reader.read_metadata(reader.metadata()[1]).values.at("log_time"), "device");

  ASSERT_FALSE(play(file, {{"host_time", "recorded"}}).failed);
  for (TestFrame& frame : frames_) frame.host_timestamp_ns = frame.depth_timestamp_ns;
  expect_played(PixelFormat::kBgr8, 0, frames_.size());
}

// Through the runtime every frame has a host time (it stamps those without); a frame
// handed to the stage without one is logged at its depth device time, not at 0.
TEST_F(McapStagesTest, AFrameWithoutHostTimeIsLoggedAtItsDeviceTime) {
  frames_ = make_frames(2, small_calibration(), 3);
  const fs::path file = dir_.path() / "unknown-host.mcap";
  StageInstance writer = direct_writer(file);
  auto& sink = dynamic_cast<Sink&>(*writer.stage);
  const auto consume = [&](const TestFrame& frame, std::int64_t host_timestamp_ns) {
    const FrameInfo info{0, frame.index, frame.depth_timestamp_ns, host_timestamp_ns};
    RawTofFrame raw;
    raw.gray = frame.depth;
    raw.device_timestamp_ns = frame.depth_timestamp_ns;
    ColorImage color;
    color.pixels = frame.color;
    color.device_timestamp_ns = frame.color_timestamp_ns;
    const std::vector<Packet> inputs{Packet(info, std::make_shared<RawTofFrame>(raw)),
                                     Packet(info, std::make_shared<ColorImage>(color)),
                                     Packet(),
                                     Packet(),
                                     Packet(),
                                     Packet(),
                                     Packet()};
    sink.consume(Frame(info, inputs, {}));
  };
  consume(frames_[0], 0);
  try {
    consume(frames_[1], -5);
    ADD_FAILURE() << "a negative host time was recorded";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(), "host timestamp -5 ns; expected >= 0 (MCAP times are unsigned)");
  }
  sink.finish();
  const auto messages = messages_of(file);
  ASSERT_EQ(messages.size(), 5u);  // the rig's 3, raw and colour
  for (const auto& [topic, message] : messages) {
    EXPECT_EQ(message.log_time, 1'000'000'000u) << topic;
  }
}

// An invalid distance is recorded with its cause and no number, and the cameras' health
// beside it; both at the frame's log time, stamped with its depth device time.
TEST_F(McapStagesTest, RecordsTheDistanceAndTheCamerasHealthAsJson) {
  frames_ = make_frames(1, small_calibration(), 3);
  const fs::path file = dir_.path() / "measured.mcap";
  StageInstance writer = direct_writer(file);
  auto& sink = dynamic_cast<Sink&>(*writer.stage);
  const TestFrame& frame = frames_[0];
  const FrameInfo info{0, frame.index, frame.depth_timestamp_ns, 1'763'800'000'000'000'000};
  auto raw = std::make_shared<RawTofFrame>();
  raw->gray = frame.depth;
  raw->device_timestamp_ns = frame.depth_timestamp_ns;
  auto color = std::make_shared<ColorImage>();
  color->pixels = frame.color;
  color->device_timestamp_ns = frame.color_timestamp_ns;
  auto distance = std::make_shared<GroundDistance>();
  distance->distance_mm = 512.5;
  distance->soil_fraction = 0.004;
  distance->invalidate(InvalidCause::kTooLittleSoil, "0.4 % of the region is soil < 5 %");
  auto cameras = std::make_shared<CameraStatus>();
  cameras->camera = "depth+color";
  cameras->problem = "depth: no frame for 2.0 s";
  cameras->completed = 41;
  cameras->lost = 3;
  const std::vector<Packet> inputs{
      Packet(info, raw), Packet(info, color),  Packet(), Packet(info, distance), Packet(),
      Packet(),          Packet(info, cameras)};
  sink.consume(Frame(info, inputs, {}));
  sink.finish();

  std::map<std::string, json> recorded;
  for (const auto& [topic, message] : messages_of(file)) {
    if (topic == "/tilth/distance" || topic == "/tilth/cameras") {
      EXPECT_EQ(message.log_time, 1'763'800'000'000'000'000u) << topic;
      EXPECT_EQ(stamp_of(topic, message), frame.depth_timestamp_ns) << topic;
      recorded[topic] = json::parse(message.data);
    }
  }
  ASSERT_EQ(recorded.size(), 2u);
  const json& d = recorded["/tilth/distance"];
  EXPECT_TRUE(d["distance_mm"].is_null());
  EXPECT_EQ(d["valid"], false);
  EXPECT_EQ(d["invalid_cause"], "too_little_soil");
  EXPECT_EQ(d["invalid_reason"], "0.4 % of the region is soil < 5 %");
  EXPECT_EQ(d["soil_fraction"], 0.004);
  EXPECT_TRUE(d["tilt_x_deg"].is_null());
  const json& c = recorded["/tilth/cameras"];
  EXPECT_EQ(c["camera"], "depth+color");
  EXPECT_EQ(c["streaming"], false);
  EXPECT_EQ(c["problem"], "depth: no frame for 2.0 s");
  EXPECT_EQ(c["completed"], 41);
  EXPECT_EQ(c["lost"], 3);
  mcap::McapReader reader(file);
  for (const auto& [id, channel] : reader.channels()) {
    if (channel.topic == "/tilth/distance") {
      EXPECT_EQ(reader.schemas().at(channel.schema_id).name, "tilth.GroundDistance");
    }
    if (channel.topic == "/tilth/cameras") {
      EXPECT_EQ(reader.schemas().at(channel.schema_id).name, "tilth.CameraStatus");
    }
  }
}

// NTP may step the host clock back during a recording: frames still play in the order
// they were recorded, not sorted by log time.
TEST_F(McapStagesTest, PlaysChunksInTheOrderWrittenWhenTheHostClockStepsBack) {
  frames_ = make_frames(4, small_calibration(), 3);
  frames_[2].host_timestamp_ns = frames_[0].host_timestamp_ns - 5'000'000'000;
  frames_[3].host_timestamp_ns = frames_[2].host_timestamp_ns + 100'000'000;
  const fs::path file = dir_.path() / "stepped.mcap";
  ASSERT_FALSE(record(file, PixelFormat::kBgr8, {{"chunk_size", 1}}).failed);
  const RunResult played = play(file, {{"host_time", "recorded"}});
  ASSERT_FALSE(played.failed) << played.failure;
  expect_played(PixelFormat::kBgr8, 0, frames_.size());
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
