// recording.image_folder_writer: round trips source -> writer -> source keep every pixel,
// timestamp (device and host) and truth; the files it writes; the frames it refuses; a
// folder it will not overwrite; and that each frame is on disk before the next one arrives.
#include <algorithm>
#include <functional>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "recording_fixture.h"
#include "tilth/calibration.h"

namespace tilth::testing {
namespace {

using nlohmann::json;

json edge(const std::string& from, const std::string& to) { return json::array({from, to}); }

json writer_node(const fs::path& folder, json params) {
  params["path"] = folder.string();
  return {{"type", "recording.image_folder_writer"}, {"params", params}};
}

// recording.image_folder -> writer, keeping the recorded host times.
std::string copy_graph(const fs::path& from, const fs::path& to, const json& writer_params) {
  const json source_params = {{"path", from.string()}, {"host_time", "recorded"}};
  const json graph = {{"nodes",
                       {{"src", {{"type", "recording.image_folder"}, {"params", source_params}}},
                        {"w", writer_node(to, writer_params)}}},
                      {"edges", json::array({edge("src.raw", "w.raw"), edge("src.color", "w.color"),
                                             edge("src.truth", "w.truth")})}};
  return graph.dump();
}

// test.feed -> writer, with or without the truth edge.
std::string feed_graph(const fs::path& to, const json& writer_params, bool with_truth = true,
                       const std::string& on_error = "stop") {
  json edges = json::array({edge("in.raw", "w.raw"), edge("in.color", "w.color")});
  if (with_truth) edges.push_back(edge("in.truth", "w.truth"));
  const json graph = {
      {"nodes", {{"in", {{"type", "test.feed"}}}, {"w", writer_node(to, writer_params)}}},
      {"edges", edges},
      {"runtime", {{"on_error", on_error}}}};
  return graph.dump();
}

// recording.image_folder -> capture, with the recorded host times.
std::string replay_graph(const fs::path& folder) {
  const json params = {{"path", folder.string()}, {"host_time", "recorded"}};
  const json graph = {
      {"nodes",
       {{"src", {{"type", "recording.image_folder"}, {"params", params}}},
        {"out", {{"type", "test.capture"}}}}},
      {"edges", json::array({edge("src.raw", "out.raw"), edge("src.color", "out.color"),
                             edge("src.truth", "out.truth")})}};
  return graph.dump();
}

Feed feed_of(const TestFrame& frame, PixelFormat format) {
  Feed feed;
  feed.frame_id = frame.index;
  feed.host_timestamp_ns = frame.host_timestamp_ns;
  feed.raw.gray = frame.depth;
  feed.raw.device_timestamp_ns = frame.depth_timestamp_ns;
  feed.color.pixels = frame.color;
  feed.color.format = format;
  feed.color.device_timestamp_ns = frame.color_timestamp_ns;
  GroundTruth truth;
  truth.distance_mm = frame.ground_truth_mm;
  truth.residue_mask = frame.mask;
  feed.truth = truth;
  return feed;
}

const std::string kHeader =
    "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm\n";
const std::string kHostHeader = "index,host_timestamp_ns\n";

class ImageFolderWriterTest : public RecordingTest {
 protected:
  ImageFolderWriterTest() { write_text(calibration_file_, small_calibration().dump(2)); }

  // Replays `folder` and checks that it holds exactly `frames_`.
  void expect_recording_holds_frames(const fs::path& folder, PixelFormat format) {
    captured_.clear();
    const RunResult result = run(replay_graph(folder));
    ASSERT_FALSE(result.failed) << result.failure;
    ASSERT_EQ(captured_.size(), frames_.size());
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      SCOPED_TRACE("frame " + std::to_string(i));
      const TestFrame& expected = frames_[i];
      const Captured& got = captured_[i];
      EXPECT_EQ(got.info.frame_id, expected.index);
      EXPECT_EQ(got.info.host_timestamp_ns, expected.host_timestamp_ns);
      EXPECT_TRUE(same_pixels(expected.depth, got.raw->gray));
      EXPECT_EQ(got.raw->device_timestamp_ns, expected.depth_timestamp_ns);
      EXPECT_TRUE(same_pixels(expected.color, got.color->pixels));
      EXPECT_EQ(got.color->format, format);
      EXPECT_EQ(got.color->device_timestamp_ns, expected.color_timestamp_ns);
      EXPECT_EQ(got.truth->distance_mm, expected.ground_truth_mm);
      if (expected.mask.empty()) {
        EXPECT_TRUE(got.truth->residue_mask.empty());
      } else {
        EXPECT_TRUE(same_pixels(expected.mask, got.truth->residue_mask));
      }
    }
  }

  std::string writer_failure(const std::string& frame_and_message) const {
    return "node 'w' (recording.image_folder_writer) failed on frame " + frame_and_message +
           "; stopping (on_error: stop)";
  }

  const fs::path calibration_file_ = dir_.path() / "small.calib.json";
  const fs::path original_ = dir_.path() / "original";
  const fs::path copy_ = dir_.path() / "copy";
  std::vector<TestFrame> frames_;
};

TEST_F(ImageFolderWriterTest, RoundTripKeepsEveryPixelTimestampAndTruth) {
  frames_ = make_frames(5, small_calibration(), 3);
  write_recording(original_, frames_, "bgr8", small_calibration());
  write_host_timestamps(original_, frames_);
  const RunResult result = run(copy_graph(
      original_, copy_, {{"calibration", calibration_file_.string()}, {"description", "a copy"}}));
  ASSERT_FALSE(result.failed) << result.failure;

  EXPECT_EQ(
      read_text(copy_ / "frames.csv"),
      kHeader +
          "3,1000000000,1000400000,depth/000003.png,color/000003.png,mask/000003.png,500.00\n"
          "4,1100000000,1100400000,depth/000004.png,color/000004.png,,\n"
          "6,1200000000,1200400000,depth/000006.png,color/000006.png,mask/000006.png,500.50\n"
          "7,1300000000,1300400000,depth/000007.png,color/000007.png,,\n"
          "8,1400000000,1400400000,depth/000008.png,color/000008.png,mask/000008.png,501.00\n");
  EXPECT_EQ(read_text(copy_ / "host_timestamps.csv"), kHostHeader +
                                                          "3,1763800000002000000\n"
                                                          "4,1763800000102000000\n"
                                                          "6,1763800000202000000\n"
                                                          "7,1763800000302000000\n"
                                                          "8,1763800000402000000\n");
  const json expected_recording = {{"format", "tilth-image-folder/1"},
                                   {"calibration", "rig.calib.json"},
                                   {"color_format", "bgr8"},
                                   {"description", "a copy"}};
  EXPECT_EQ(json::parse(read_text(copy_ / "recording.json")), expected_recording);
  EXPECT_EQ(read_text(copy_ / "rig.calib.json"), read_text(calibration_file_));
  EXPECT_FALSE(fs::exists(copy_ / "mask" / "000004.png"));
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

TEST_F(ImageFolderWriterTest, RoundTripOfABayerRecordingAtFullSize) {
  const json calibration = json::parse(read_text(shipped_calibration_file()));
  frames_ = make_frames(2, calibration, 1);
  write_recording(original_, frames_, "bayer_rggb8", calibration);
  write_host_timestamps(original_, frames_);
  const RunResult result =
      run(copy_graph(original_, copy_, {{"calibration", shipped_calibration_file().string()}}));
  ASSERT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(json::parse(read_text(copy_ / "recording.json"))["color_format"], "bayer_rggb8");
  EXPECT_EQ(cv::imread((copy_ / "color/000003.png").string(), cv::IMREAD_UNCHANGED).type(),
            CV_8UC1);
  expect_recording_holds_frames(copy_, PixelFormat::kBayerRggb8);
}

TEST_F(ImageFolderWriterTest, GroundTruthKeepsEveryDigitAndAtLeastTwoDecimals) {
  frames_ = make_frames(3, small_calibration(), 3);
  frames_[0].ground_truth_mm = 518.123456789;
  frames_[1].ground_truth_mm = 0.1;
  frames_[2].ground_truth_mm = 1234.5;
  for (const auto& frame : frames_) feed_.push_back(feed_of(frame, PixelFormat::kBgr8));
  const RunResult result = run(feed_graph(copy_, {{"calibration", calibration_file_.string()}}));
  ASSERT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(read_text(copy_ / "frames.csv"),
            kHeader +
                "3,1000000000,1000400000,depth/000003.png,color/000003.png,mask/000003.png,"
                "518.123456789\n"
                "4,1100000000,1100400000,depth/000004.png,color/000004.png,,0.10\n"
                "6,1200000000,1200400000,depth/000006.png,color/000006.png,mask/000006.png,"
                "1234.50\n");
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

TEST_F(ImageFolderWriterTest, Rgb8IsStoredAsBgr8) {
  frames_ = make_frames(2, small_calibration(), 3);
  for (const auto& frame : frames_) feed_.push_back(feed_of(frame, PixelFormat::kRgb8));
  const RunResult result = run(feed_graph(copy_, {{"calibration", calibration_file_.string()}}));
  ASSERT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(json::parse(read_text(copy_ / "recording.json"))["color_format"], "bgr8");
  cv::Mat expected_bgr;
  cv::cvtColor(frames_[1].color, expected_bgr, cv::COLOR_RGB2BGR);
  EXPECT_TRUE(same_pixels(expected_bgr,
                          cv::imread((copy_ / "color/000004.png").string(), cv::IMREAD_UNCHANGED)));
  EXPECT_FALSE(same_pixels(frames_[1].color, expected_bgr));
}

TEST_F(ImageFolderWriterTest, Mono8CannotBeRecorded) {
  frames_ = make_frames(1, small_calibration(), 1);
  feed_.push_back(feed_of(frames_[0], PixelFormat::kMono8));
  const RunResult result = run(feed_graph(copy_, {{"calibration", calibration_file_.string()}}));
  EXPECT_EQ(result.failure,
            writer_failure("3 (sequence 0): color: mono8 cannot be recorded; expected bgr8, rgb8 "
                           "(stored as bgr8) or a Bayer mosaic"));
}

// A camera reading out a window of its colour sensor: the recording holds the window's
// pixels, the rig's calibration as given and the window in recording.json, and replay
// gives each image its place on the sensor again, so that it registers as live; a window
// off the image's centre records as well; a frame of another window is refused.
TEST_F(ImageFolderWriterTest, AColourWindowIsRecordedAndReplayedWhereItLies) {
  for (const cv::Rect& window : {cv::Rect(10, 6, 24, 20), cv::Rect(30, 0, 10, 8)}) {
    SCOPED_TRACE(window_text(window));
    frames_ = make_frames(3, small_calibration(), 3);
    feed_.clear();
    for (TestFrame& frame : frames_) {
      feed_.push_back(feed_of(frame, PixelFormat::kBgr8));
      feed_.back().color.pixels = frame.color(window).clone();
      feed_.back().color.sensor_offset = window.tl();
      frame.color = frame.color(window).clone();
    }
    const fs::path folder = dir_.path() / ("window" + std::to_string(window.x));
    const RunResult result = run(feed_graph(folder, {{"calibration", calibration_file_.string()}}));
    ASSERT_FALSE(result.failed) << result.failure;
    EXPECT_EQ(read_text(folder / "rig.calib.json"), read_text(calibration_file_));
    const json stored = {
        {"x", window.x}, {"y", window.y}, {"width", window.width}, {"height", window.height}};
    EXPECT_EQ(json::parse(read_text(folder / "recording.json"))["color_window"], stored);
    expect_recording_holds_frames(folder, PixelFormat::kBgr8);
    for (const Captured& replayed : captured_) {
      EXPECT_EQ(replayed.color->sensor_offset, window.tl());
    }
  }

  const cv::Rect window(10, 6, 24, 20);
  frames_ = make_frames(2, small_calibration(), 3);
  feed_.clear();
  for (const TestFrame& frame : frames_) feed_.push_back(feed_of(frame, PixelFormat::kBgr8));
  feed_[0].color.pixels = frames_[0].color(window).clone();
  feed_[0].color.sensor_offset = window.tl();
  feed_[1].color.sensor_offset = cv::Point(0, 0);
  EXPECT_EQ(run(feed_graph(dir_.path() / "changed", {{"calibration", calibration_file_.string()}}))
                .failure,
            writer_failure("4 (sequence 1): color: the sensor's 40x30 px at (0, 0); expected "
                           "24x20 px at (10, 6) as in the first frame (a recording has one "
                           "colour window)"));

  feed_.resize(1);
  feed_[0].color.pixels = frames_[0].color(window).clone();
  feed_[0].color.sensor_offset = cv::Point(20, 20);
  EXPECT_EQ(run(feed_graph(dir_.path() / "outside", {{"calibration", calibration_file_.string()}}))
                .failure,
            writer_failure("3 (sequence 0): color: the sensor's 24x20 px at (20, 20) is not "
                           "inside the calibration's 40x30 px colour image"));
}

// A first frame refused after its window was looked at (here for its mask) leaves the
// recording's window to the first frame written.
TEST_F(ImageFolderWriterTest, ARefusedFirstFrameDoesNotFixTheColourWindow) {
  frames_ = make_frames(2, small_calibration(), 3);
  feed_.push_back(feed_of(frames_[0], PixelFormat::kBgr8));
  feed_[0].color.pixels = frames_[0].color(cv::Rect(10, 6, 24, 20)).clone();
  feed_[0].color.sensor_offset = cv::Point(10, 6);
  feed_[0].truth->residue_mask = cv::Mat(1, 1, CV_8UC1);
  feed_.push_back(feed_of(frames_[1], PixelFormat::kBgr8));
  const RunResult result =
      run(feed_graph(copy_, {{"calibration", calibration_file_.string()}}, true, "skip"));
  EXPECT_FALSE(result.failed);
  EXPECT_EQ(result.metrics.stages[1].errors, 1u);
  EXPECT_FALSE(json::parse(read_text(copy_ / "recording.json")).contains("color_window"));
  frames_.erase(frames_.begin());
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

// The first frame fixes color_format; a frame in another format is refused before any of
// its files is written.
TEST_F(ImageFolderWriterTest, ColorFormatMustNotChange) {
  frames_ = make_frames(2, small_calibration(), 1);
  feed_.push_back(feed_of(frames_[0], PixelFormat::kBayerBggr8));
  feed_.push_back(feed_of(frames_[1], PixelFormat::kBayerGbrg8));
  const RunResult result = run(feed_graph(copy_, {{"calibration", calibration_file_.string()}}));
  EXPECT_EQ(result.failure,
            writer_failure("4 (sequence 1): color: expected bayer_bggr8 as in the first frame (a "
                           "recording has one color_format), got bayer_gbrg8"));
  EXPECT_EQ(
      read_text(copy_ / "frames.csv"),
      kHeader +
          "3,1000000000,1000400000,depth/000003.png,color/000003.png,mask/000003.png,500.00\n");
  EXPECT_FALSE(fs::exists(copy_ / "depth/000004.png"));
  EXPECT_EQ(json::parse(read_text(copy_ / "recording.json"))["color_format"], "bayer_bggr8");
}

TEST_F(ImageFolderWriterTest, ARefusedFirstFrameDoesNotFixTheColorFormat) {
  frames_ = make_frames(2, small_calibration(), 1);
  feed_.push_back(feed_of(frames_[0], PixelFormat::kBayerBggr8));
  feed_[0].truth->residue_mask = cv::Mat(1, 1, CV_8UC1);
  frames_ = make_frames(2, small_calibration(), 3);
  feed_.push_back(feed_of(frames_[1], PixelFormat::kBgr8));
  const RunResult result =
      run(feed_graph(copy_, {{"calibration", calibration_file_.string()}}, true, "skip"));
  EXPECT_FALSE(result.failed);
  EXPECT_EQ(result.metrics.stages[1].errors, 1u);
  EXPECT_EQ(json::parse(read_text(copy_ / "recording.json"))["color_format"], "bgr8");
  frames_.erase(frames_.begin());
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

TEST_F(ImageFolderWriterTest, RefusesWhatTheReaderWouldRefuse) {
  const auto failure_for = [&](const std::function<void(std::vector<Feed>&)>& spoil) {
    frames_ = make_frames(2, small_calibration(), 3);
    feed_.clear();
    for (const auto& frame : frames_) feed_.push_back(feed_of(frame, PixelFormat::kBgr8));
    spoil(feed_);
    return run(feed_graph(copy_,
                          {{"calibration", calibration_file_.string()}, {"overwrite", true}}))
        .failure;
  };
  EXPECT_EQ(failure_for([](auto& feed) { feed[1].frame_id = 3; }),
            writer_failure("3 (sequence 1): frame id: expected a value > 3 (the previous "
                           "frame's), got 3"));
  EXPECT_EQ(failure_for([](auto& feed) { feed[1].raw.device_timestamp_ns = 999; }),
            writer_failure("4 (sequence 1): raw device timestamp: expected a value > 1000000000 "
                           "(the previous frame's), got 999"));
  EXPECT_EQ(failure_for([](auto& feed) { feed[1].color.device_timestamp_ns = 1000400000; }),
            writer_failure("4 (sequence 1): color device timestamp: expected a value > "
                           "1000400000 (the previous frame's), got 1000400000"));
  EXPECT_EQ(failure_for([](auto& feed) { feed[1].host_timestamp_ns = -5; }),
            writer_failure("4 (sequence 1): host timestamp -5 ns; expected >= 0 "
                           "(CLOCK_REALTIME)"));
  EXPECT_EQ(failure_for([](auto& feed) { feed[0].raw.gray = cv::Mat(12, 16, CV_16UC1); }),
            writer_failure("3 (sequence 0): raw: expected 16-bit 1-channel, 32x24 pixels "
                           "(depth_camera in the calibration), got 16-bit 1-channel, 16x12 "
                           "pixels"));
  EXPECT_EQ(failure_for([](auto& feed) { feed[0].color.pixels = cv::Mat(30, 40, CV_8UC4); }),
            writer_failure("3 (sequence 0): color: expected 8-bit 3-channel, 40x30 pixels "
                           "(color_camera in the calibration), got 8-bit 4-channel, 40x30 "
                           "pixels"));
  EXPECT_EQ(failure_for([](auto& feed) { feed[0].truth->residue_mask = cv::Mat(24, 32, CV_8UC3); }),
            writer_failure("3 (sequence 0): truth mask: expected 8-bit 1-channel, 32x24 pixels "
                           "(depth_camera in the calibration), got 8-bit 3-channel, 32x24 "
                           "pixels"));
}

TEST_F(ImageFolderWriterTest, TruthIsOptional) {
  frames_ = make_frames(3, small_calibration(), 3);
  for (const auto& frame : frames_) feed_.push_back(feed_of(frame, PixelFormat::kBgr8));
  feed_[2].truth.reset();  // no truth message for this frame
  ASSERT_FALSE(run(feed_graph(copy_, {{"calibration", calibration_file_.string()}})).failed);
  EXPECT_EQ(read_text(copy_ / "frames.csv"),
            kHeader +
                "3,1000000000,1000400000,depth/000003.png,color/000003.png,mask/000003.png,500.00\n"
                "4,1100000000,1100400000,depth/000004.png,color/000004.png,,\n"
                "6,1200000000,1200400000,depth/000006.png,color/000006.png,,\n");

  const fs::path unconnected = dir_.path() / "no-truth";
  ASSERT_FALSE(
      run(feed_graph(unconnected, {{"calibration", calibration_file_.string()}}, false)).failed);
  EXPECT_EQ(read_text(unconnected / "frames.csv"),
            kHeader +
                "3,1000000000,1000400000,depth/000003.png,color/000003.png,,\n"
                "4,1100000000,1100400000,depth/000004.png,color/000004.png,,\n"
                "6,1200000000,1200400000,depth/000006.png,color/000006.png,,\n");
  EXPECT_FALSE(fs::exists(unconnected / "mask"));
}

TEST_F(ImageFolderWriterTest, ANonEmptyFolderIsReplacedOnlyWhenAskedAndOnlyARecording) {
  const std::string prefix = "node 'w' (recording.image_folder_writer) failed to start: ";
  write_text(copy_ / "notes.txt", "field 7, north end");
  EXPECT_EQ(start_error(feed_graph(copy_, {{"calibration", calibration_file_.string()}})),
            prefix + copy_.string() +
                ": folder exists and is not empty; set overwrite: true to replace the recording "
                "in it");
  EXPECT_EQ(start_error(feed_graph(
                copy_, {{"calibration", calibration_file_.string()}, {"overwrite", true}})),
            prefix + copy_.string() +
                ": folder is not empty and holds no recording.json; not overwriting a folder that "
                "is not a recording");

  // A recording of 5 frames replaced by one of 1: nothing of the old one stays but the
  // file that is not part of a recording.
  frames_ = make_frames(5, small_calibration(), 3);
  write_recording(copy_, frames_, "bgr8", small_calibration());
  write_host_timestamps(copy_, frames_);
  frames_.resize(1);
  feed_ = {feed_of(frames_[0], PixelFormat::kBgr8)};
  ASSERT_FALSE(
      run(feed_graph(copy_, {{"calibration", calibration_file_.string()}, {"overwrite", true}}))
          .failed);
  const auto count = [](const fs::path& folder) {
    return std::distance(fs::directory_iterator(folder), fs::directory_iterator());
  };
  EXPECT_EQ(count(copy_ / "depth"), 1);
  EXPECT_EQ(count(copy_ / "mask"), 1);
  EXPECT_EQ(read_text(copy_ / "notes.txt"), "field 7, north end");
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

// The writer changes nothing before it has a frame to write (or the run ends): a graph
// that fails to start leaves the recording it would have replaced.
TEST_F(ImageFolderWriterTest, AGraphThatDoesNotStartLeavesTheFolderAsItWas) {
  frames_ = make_frames(3, small_calibration(), 3);
  write_recording(copy_, frames_, "bgr8", small_calibration());
  write_host_timestamps(copy_, frames_);
  const std::string csv_before = read_text(copy_ / "frames.csv");
  const std::string error =
      start_error(copy_graph(dir_.path() / "nowhere", copy_,
                             {{"calibration", calibration_file_.string()}, {"overwrite", true}}));
  EXPECT_EQ(error, "node 'src' (recording.image_folder) failed to start: " +
                       (dir_.path() / "nowhere" / "recording.json").string() +
                       ": cannot read (is this a recording folder?)");
  EXPECT_EQ(read_text(copy_ / "frames.csv"), csv_before);
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

// The calibration may live in the folder it replaces.
TEST_F(ImageFolderWriterTest, OverwriteKeepsACalibrationFromTheFolderItReplaces) {
  frames_ = make_frames(2, small_calibration(), 3);
  write_recording(copy_, frames_, "bgr8", "rig.calib.json");
  write_text(copy_ / "rig.calib.json", small_calibration().dump(1));
  for (const auto& frame : frames_) feed_.push_back(feed_of(frame, PixelFormat::kBgr8));
  const RunResult result = run(feed_graph(
      copy_, {{"calibration", (copy_ / "rig.calib.json").string()}, {"overwrite", true}}));
  ASSERT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(read_text(copy_ / "rig.calib.json"), small_calibration().dump(1));
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
}

TEST_F(ImageFolderWriterTest, ABadCalibrationIsNamedBeforeAnythingIsWritten) {
  json calibration = small_calibration();
  calibration["depth_camera"].erase("gray_to_mm");
  write_text(calibration_file_, calibration.dump(2));
  EXPECT_EQ(start_error(feed_graph(copy_, {{"calibration", calibration_file_.string()}})),
            "node 'w' (recording.image_folder_writer) failed to start: " +
                calibration_file_.string() + ":/depth_camera/gray_to_mm: missing required field");
  EXPECT_FALSE(fs::exists(copy_));
}

// A killed writer leaves a readable recording: each frame's files and its lines in
// frames.csv and host_timestamps.csv are on disk when consume() returns. Frames that
// reach the writer without a host time (0) are recorded with their depth device time.
TEST_F(ImageFolderWriterTest, EachFrameIsOnDiskWhenConsumeReturns) {
  frames_ = make_frames(3, small_calibration(), 3);
  for (TestFrame& frame : frames_) frame.host_timestamp_ns = frame.depth_timestamp_ns;
  StageContext context{"w",
                       Params(json{{"path", copy_.string()},
                                   {"calibration", calibration_file_.string()},
                                   {"overwrite", false},
                                   {"description", ""}}),
                       Logger("w"),
                       {}};
  StageInstance writer = registry_.create("recording.image_folder_writer", context);
  auto& sink = dynamic_cast<Sink&>(*writer.stage);
  EXPECT_FALSE(fs::exists(copy_));  // nothing until there is a frame to write
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    const Feed feed = feed_of(frames_[i], PixelFormat::kBgr8);
    const FrameInfo info{i, feed.frame_id, feed.raw.device_timestamp_ns, 0};
    const std::vector<Packet> inputs{Packet(info, std::make_shared<RawTofFrame>(feed.raw)),
                                     Packet(info, std::make_shared<ColorImage>(feed.color)),
                                     Packet(info, std::make_shared<GroundTruth>(*feed.truth))};
    sink.consume(Frame(info, inputs, {}));
    for (const std::string file : {"frames.csv", "host_timestamps.csv"}) {
      const auto lines = read_text(copy_ / file);
      EXPECT_EQ(std::count(lines.begin(), lines.end(), '\n'), static_cast<long>(i + 2)) << file;
    }
    EXPECT_TRUE(fs::exists(copy_ / "recording.json"));
    const fs::path depth = copy_ / frame_file("depth", feed.frame_id);
    EXPECT_TRUE(same_pixels(frames_[i].depth, cv::imread(depth.string(), cv::IMREAD_UNCHANGED)));
  }
  // Readable before finish(), as after a kill.
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
  sink.finish();
}

TEST_F(ImageFolderWriterTest, NoFramesMakeAnEmptyValidRecording) {
  ASSERT_FALSE(run(feed_graph(copy_, {{"calibration", calibration_file_.string()}})).failed);
  EXPECT_EQ(read_text(copy_ / "frames.csv"), kHeader);
  EXPECT_EQ(read_text(copy_ / "host_timestamps.csv"), kHostHeader);
  expect_recording_holds_frames(copy_, PixelFormat::kBgr8);
  EXPECT_TRUE(captured_.empty());
}

}  // namespace
}  // namespace tilth::testing
