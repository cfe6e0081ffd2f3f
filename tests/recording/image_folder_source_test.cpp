// recording.image_folder through the real runtime: what it emits for a recording the
// test writes itself, host capture times when played or from host_timestamps.csv, the
// exact error for each kind of bad input, skipping or stopping on a missing PNG, pacing,
// interrupting a paced wait, and looping.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <sstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "recording_fixture.h"

namespace tilth::testing {
namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr std::string_view kFramesHeader =
    "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm";

// Source -> capture sink.
std::string replay_graph(const fs::path& folder, json params = json::object()) {
  params["path"] = folder.string();
  const json graph = {{"nodes",
                       {{"src", {{"type", "recording.image_folder"}, {"params", params}}},
                        {"out", {{"type", "test.capture"}}}}},
                      {"edges", json::array({json::array({"src.raw", "out.raw"}),
                                             json::array({"src.color", "out.color"}),
                                             json::array({"src.truth", "out.truth"})})},
                      {"runtime", {{"max_in_flight", 2}}}};
  return graph.dump();
}

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Replaces `file` with a FIFO that nothing writes to, removed again at the end of the
// scope. Should the code under test block opening or reading it, the writing end is
// opened and closed after 3 s, so that the test fails (an end of file instead of the
// expected error) rather than hangs.
class Fifo {
 public:
  explicit Fifo(const fs::path& file) : file_(file) {
    fs::remove(file_);
    if (::mkfifo(file_.c_str(), 0600) != 0) throw std::runtime_error("mkfifo failed");
    unblocker_ = std::thread([this] {
      const auto deadline = Clock::now() + std::chrono::seconds(3);
      while (!done_) {
        if (Clock::now() > deadline) {
          const int fd = ::open(file_.c_str(), O_WRONLY | O_NONBLOCK);
          if (fd >= 0) ::close(fd);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
      }
    });
  }
  ~Fifo() {
    done_ = true;
    unblocker_.join();
    fs::remove(file_);
  }
  Fifo(const Fifo&) = delete;
  Fifo& operator=(const Fifo&) = delete;

 private:
  const fs::path file_;
  std::atomic<bool> done_{false};
  std::thread unblocker_;
};

class ImageFolderSourceTest : public RecordingTest {
 protected:
  // A valid bgr8 recording of `count` frames with an inline calibration.
  fs::path record(int count = 5, std::int64_t spacing_ns = 100'000'000) {
    frames_ = make_frames(count, small_calibration(), 3, spacing_ns);
    write_recording(folder_, frames_, "bgr8", small_calibration());
    return folder_;
  }

  // Replaces one line of frames.csv (1 = the header).
  void replace_line(std::size_t line, const std::string& text) {
    std::istringstream in(read_text(folder_ / "frames.csv"));
    std::string result;
    std::string current;
    for (std::size_t number = 1; std::getline(in, current); ++number) {
      result += (number == line ? text : current) + "\n";
    }
    write_text(folder_ / "frames.csv", result);
  }

  void edit_recording_json(const std::function<void(json&)>& edit) {
    json document = json::parse(read_text(folder_ / "recording.json"));
    edit(document);
    write_text(folder_ / "recording.json", document.dump(2));
  }

  std::string start_failure() {
    const std::string prefix = "node 'src' (recording.image_folder) failed to start: ";
    const std::string error = start_error(replay_graph(folder_));
    return error.rfind(prefix, 0) == 0 ? error.substr(prefix.size()) : "unexpected: " + error;
  }

  std::string csv() const { return (folder_ / "frames.csv").string(); }
  std::string host_csv() const { return (folder_ / "host_timestamps.csv").string(); }
  std::string json_file() const { return (folder_ / "recording.json").string(); }

  fs::path folder_ = dir_.path() / "rec";
  std::vector<TestFrame> frames_;
};

TEST_F(ImageFolderSourceTest, EmitsEveryPixelTimestampAndTruthOfTheRecording) {
  record(5);
  const auto before = std::chrono::system_clock::now();
  const RunResult result = run(replay_graph(folder_));
  const auto after = std::chrono::system_clock::now();
  ASSERT_FALSE(result.failed) << result.failure;
  ASSERT_EQ(captured_.size(), frames_.size());
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const TestFrame& expected = frames_[i];
    const Captured& got = captured_[i];
    EXPECT_EQ(got.info.frame_id, expected.index);
    EXPECT_EQ(got.info.device_timestamp_ns, expected.depth_timestamp_ns);
    EXPECT_GE(got.info.host_timestamp_ns, before.time_since_epoch().count());
    EXPECT_LE(got.info.host_timestamp_ns, after.time_since_epoch().count());
    EXPECT_TRUE(same_pixels(expected.depth, got.raw->gray));
    EXPECT_EQ(got.raw->device_timestamp_ns, expected.depth_timestamp_ns);
    EXPECT_FALSE(got.raw->scale_mm.has_value());
    EXPECT_TRUE(same_pixels(expected.color, got.color->pixels));
    EXPECT_EQ(got.color->format, PixelFormat::kBgr8);
    EXPECT_EQ(got.color->device_timestamp_ns, expected.color_timestamp_ns);
    ASSERT_NE(got.truth, nullptr);
    EXPECT_EQ(got.truth->distance_mm, expected.ground_truth_mm);
    if (expected.mask.empty()) {
      EXPECT_TRUE(got.truth->residue_mask.empty());
    } else {
      EXPECT_TRUE(same_pixels(expected.mask, got.truth->residue_mask));
    }
  }
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3, 4, 6, 7, 8}));
  // The comparisons above did compare values, not two absent truths.
  EXPECT_EQ(frames_[0].ground_truth_mm, 500.0);
  EXPECT_EQ(frames_[4].ground_truth_mm, 501.0);
}

TEST_F(ImageFolderSourceTest, BayerMosaicWithACalibrationFileInTheFolder) {
  const json calibration = json::parse(read_text(shipped_calibration_file()));
  frames_ = make_frames(2, calibration, 1);
  write_recording(folder_, frames_, "bayer_grbg8", "calib/rig.calib.json");
  fs::create_directories(folder_ / "calib");
  fs::copy_file(shipped_calibration_file(), folder_ / "calib" / "rig.calib.json");
  const RunResult result = run(replay_graph(folder_));
  ASSERT_FALSE(result.failed) << result.failure;
  ASSERT_EQ(captured_.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(captured_[i].color->format, PixelFormat::kBayerGrbg8);
    EXPECT_EQ(captured_[i].color->pixels.type(), CV_8UC1);
    EXPECT_TRUE(same_pixels(frames_[i].color, captured_[i].color->pixels));
    EXPECT_TRUE(same_pixels(frames_[i].depth, captured_[i].raw->gray));
    EXPECT_EQ(captured_[i].raw->gray.size(), cv::Size(640, 480));
  }
}

TEST_F(ImageFolderSourceTest, TruthIsEmptyWithoutMaskAndGroundTruthColumns) {
  record(2);
  write_text(folder_ / "frames.csv",
             "index,depth_timestamp_ns,color_timestamp_ns,depth,color\n"
             "3,1000000000,1000400000,depth/000003.png,color/000003.png\n"
             "4,1100000000,1100400000,depth/000004.png,color/000004.png\n");
  const RunResult result = run(replay_graph(folder_));
  ASSERT_FALSE(result.failed) << result.failure;
  ASSERT_EQ(captured_.size(), 2u);
  for (const auto& got : captured_) {
    ASSERT_NE(got.truth, nullptr);
    EXPECT_FALSE(got.truth->distance_mm.has_value());
    EXPECT_TRUE(got.truth->residue_mask.empty());
  }
}

TEST_F(ImageFolderSourceTest, MissingFilesAreNamed) {
  record(1);
  fs::remove(folder_ / "frames.csv");
  EXPECT_EQ(start_failure(), csv() + ": cannot read (is this a recording folder?)");
  fs::remove(folder_ / "recording.json");
  EXPECT_EQ(start_failure(), json_file() + ": cannot read (is this a recording folder?)");
}

TEST_F(ImageFolderSourceTest, RecordingJsonErrorsNameTheFieldAndWhatWasExpected) {
  record(1);
  edit_recording_json([](json& d) { d["format"] = "tilth-image-folder/2"; });
  EXPECT_EQ(start_failure(), json_file() +
                                 ":/format: expected \"tilth-image-folder/1\", got "
                                 "\"tilth-image-folder/2\"");

  edit_recording_json([](json& d) {
    d["format"] = "tilth-image-folder/1";
    d["color_format"] = "rgb8";
  });
  EXPECT_EQ(start_failure(), json_file() +
                                 ":/color_format: expected one of bgr8, bayer_rggb8, bayer_bggr8, "
                                 "bayer_grbg8, bayer_gbrg8, got \"rgb8\"");

  edit_recording_json([](json& d) {
    d["color_format"] = "bgr8";
    d["calibration"]["depth_camera"]["fx"] = 0;
  });
  EXPECT_EQ(start_failure(),
            json_file() + ":/calibration:/depth_camera/fx: expected a number > 0, got 0");

  edit_recording_json([](json& d) { d["calibration"] = "missing.calib.json"; });
  EXPECT_EQ(start_failure(),
            (folder_ / "missing.calib.json").string() + ": cannot read calibration file");

  edit_recording_json([](json& d) { d["calibration"] = 7; });
  EXPECT_EQ(start_failure(), json_file() +
                                 ":/calibration: expected a calibration file name relative to the "
                                 "folder, or a calibration object, got 7");

  edit_recording_json([](json& d) { d.erase("calibration"); });
  EXPECT_EQ(start_failure(), json_file() + ":/calibration: missing required field");

  edit_recording_json([](json& d) { d["colour_format"] = "bgr8"; });
  EXPECT_EQ(start_failure(), json_file() + ":/colour_format: no such field (misspelt?)");
}

// color_window must be a window inside the calibration's colour image, and the colour
// PNGs its size.
TEST_F(ImageFolderSourceTest, AColourWindowIsCheckedAgainstTheCalibrationAndThePngs) {
  record(1);
  const std::string expected =
      ":/color_window: expected {\"x\", \"y\", \"width\", \"height\"} in pixels, inside "
      "the calibration's 40x30 px colour image, got ";
  for (const auto& [window, got] : std::vector<std::pair<json, std::string>>{
           {json{{"x", 30}, {"y", 0}, {"width", 20}, {"height", 8}},
            R"({"height":8,"width":20,"x":30,"y":0})"},
           {json{{"x", -1}, {"y", 0}, {"width", 20}, {"height", 8}},
            R"({"height":8,"width":20,"x":-1,"y":0})"},
           {json{{"x", 0}, {"y", 0}, {"width", 20}}, R"({"width":20,"x":0,"y":0})"},
           {json{{"x", 0}, {"y", 0}, {"width", 0}, {"height", 8}},
            R"({"height":8,"width":0,"x":0,"y":0})"},
           {json::array({0, 0, 20, 8}), "[0,0,20,8]"}}) {
    edit_recording_json([&](json& d) { d["color_window"] = window; });
    EXPECT_EQ(start_failure(), json_file() + expected + got);
  }
  // A window inside the image, but the PNGs are the whole image.
  edit_recording_json([](json& d) {
    d["color_window"] = {{"x", 4}, {"y", 2}, {"width", 20}, {"height", 8}};
  });
  const RunResult result = run(replay_graph(folder_));
  EXPECT_NE(result.failure.find("(color_window in recording.json)"), std::string::npos)
      << result.failure;
}

// The last "color_format" was kept: the frames were read as Bayer mosaics.
TEST_F(ImageFolderSourceTest, RecordingJsonWithADuplicateKeyIsRefused) {
  record(1);
  std::string text = read_text(folder_ / "recording.json");
  text.replace(text.rfind('}'), 1, ", \"color_format\": \"bayer_rggb8\"}");
  write_text(folder_ / "recording.json", text);
  EXPECT_EQ(start_failure(), json_file() +
                                 ":/color_format: expected each key once in an object, got "
                                 "\"color_format\" again");
}

TEST_F(ImageFolderSourceTest, ReferencedCalibrationErrorsNameItsFile) {
  record(1);
  json calibration = small_calibration();
  calibration["depth_camera"]["depth_measure"] = "radial_distance";
  write_text(folder_ / "rig.calib.json", calibration.dump(2));
  edit_recording_json([](json& d) { d["calibration"] = "rig.calib.json"; });
  EXPECT_EQ(start_failure(), (folder_ / "rig.calib.json").string() +
                                 ":/depth_camera/depth_measure: expected \"radial\" or \"z\", got "
                                 "\"radial_distance\"");
}

TEST_F(ImageFolderSourceTest, FramesCsvErrorsNameTheLineAndWhatWasExpected) {
  const std::string all_columns =
      "(expected columns index, depth_timestamp_ns, color_timestamp_ns, depth, color and "
      "optionally mask, ground_truth_mm)";
  record(4);
  const std::string header =
      "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm";
  replace_line(1, "index,depth_timestamp_ns,depth,color,mask,ground_truth_mm");
  EXPECT_EQ(start_failure(),
            csv() + ":1: missing required column 'color_timestamp_ns' " + all_columns);

  replace_line(1, header + ",exposure_us");
  EXPECT_EQ(start_failure(), csv() + ":1: unknown column 'exposure_us' " + all_columns);

  replace_line(1, "index,depth,depth_timestamp_ns,color_timestamp_ns,depth,color,mask");
  EXPECT_EQ(start_failure(), csv() + ":1: column 'depth' appears twice");

  record(4);
  replace_line(3, "4,11000O0000,1100400000,depth/000004.png,color/000004.png,,");
  EXPECT_EQ(start_failure(), csv() +
                                 ":3: column 'depth_timestamp_ns': expected an integer number of "
                                 "nanoseconds, got '11000O0000'");

  replace_line(3, "-4,1100000000,1100400000,depth/000004.png,color/000004.png,,");
  EXPECT_EQ(start_failure(),
            csv() + ":3: column 'index': expected a non-negative integer, got '-4'");

  replace_line(3, "4,1100000000,1100400000,depth/000004.png,color/000004.png,,5l8");
  EXPECT_EQ(start_failure(), csv() +
                                 ":3: column 'ground_truth_mm': expected a number of millimetres "
                                 "or nothing, got '5l8'");

  replace_line(3, "4,1100000000,1100400000,depth/000004.png,color/000004.png,");
  EXPECT_EQ(start_failure(), csv() + ":3: expected 7 fields as in the header, got 6");

  replace_line(3, "4,1100000000,1100400000,,color/000004.png,,");
  EXPECT_EQ(start_failure(), csv() +
                                 ":3: column 'depth': expected a file path relative to the "
                                 "recording folder, got ''");
}

TEST_F(ImageFolderSourceTest, IndicesAndTimestampsMustIncrease) {
  record(4);  // lines 2..5: indices 3, 4, 6, 7; depth 1.0 s, 1.1 s, 1.2 s, 1.3 s
  replace_line(4, "6,1050000000,1200400000,depth/000006.png,color/000006.png,,");
  EXPECT_EQ(start_failure(), csv() +
                                 ":4: column 'depth_timestamp_ns': expected a value > 1100000000 "
                                 "(line 3), got '1050000000'");

  replace_line(4, "6,1200000000,1100400000,depth/000006.png,color/000006.png,,");
  EXPECT_EQ(start_failure(), csv() +
                                 ":4: column 'color_timestamp_ns': expected a value > 1100400000 "
                                 "(line 3), got '1100400000'");

  replace_line(4, "4,1200000000,1200400000,depth/000006.png,color/000006.png,,");
  EXPECT_EQ(start_failure(), csv() + ":4: column 'index': expected a value > 4 (line 3), got '4'");
}

// By default, as live: the host clock when each frame is played, whatever the folder
// recorded.
TEST_F(ImageFolderSourceTest, HostTimesAreWhenPlayedByDefault) {
  record(4);
  write_host_timestamps(folder_, frames_);
  for (const json& params : {json::object(), json{{"host_time", "replayed"}}}) {
    SCOPED_TRACE(params.dump());
    captured_.clear();
    const auto before = std::chrono::system_clock::now().time_since_epoch().count();
    const RunResult result = run(replay_graph(folder_, params));
    const auto after = std::chrono::system_clock::now().time_since_epoch().count();
    ASSERT_FALSE(result.failed) << result.failure;
    ASSERT_EQ(captured_.size(), frames_.size());
    for (std::size_t i = 0; i < frames_.size(); ++i) {
      EXPECT_GE(captured_[i].info.host_timestamp_ns, before) << i;
      EXPECT_LE(captured_[i].info.host_timestamp_ns, after) << i;
      EXPECT_NE(captured_[i].info.host_timestamp_ns, frames_[i].host_timestamp_ns) << i;
    }
  }
}

TEST_F(ImageFolderSourceTest, RecordedHostTimesComeFromHostTimestampsCsv) {
  record(4);
  // As written on Windows, with an empty line.
  std::string csv = "index,host_timestamp_ns\r\n\r\n";
  for (const TestFrame& frame : frames_) {
    csv += std::to_string(frame.index) + "," + std::to_string(frame.host_timestamp_ns) + "\r\n";
  }
  write_text(folder_ / "host_timestamps.csv", csv);
  const RunResult result = run(replay_graph(folder_, {{"host_time", "recorded"}}));
  ASSERT_FALSE(result.failed) << result.failure;
  ASSERT_EQ(captured_.size(), frames_.size());
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    EXPECT_EQ(captured_[i].info.host_timestamp_ns, frames_[i].host_timestamp_ns) << i;
    EXPECT_EQ(captured_[i].info.device_timestamp_ns, frames_[i].depth_timestamp_ns) << i;
  }
  EXPECT_EQ(frames_[3].host_timestamp_ns, 1'763'800'000'302'000'000);
}

// A folder without host_timestamps.csv recorded no host times: frames are stamped as
// they are played.
TEST_F(ImageFolderSourceTest, RecordedHostTimesWithoutHostTimestampsCsvAreWhenPlayed) {
  record(3);
  const auto before = std::chrono::system_clock::now().time_since_epoch().count();
  const RunResult result = run(replay_graph(folder_, {{"host_time", "recorded"}}));
  const auto after = std::chrono::system_clock::now().time_since_epoch().count();
  ASSERT_FALSE(result.failed) << result.failure;
  ASSERT_EQ(captured_.size(), frames_.size());
  for (const Captured& got : captured_) {
    EXPECT_GE(got.info.host_timestamp_ns, before) << got.info.frame_id;
    EXPECT_LE(got.info.host_timestamp_ns, after) << got.info.frame_id;
  }
}

TEST_F(ImageFolderSourceTest, AnUnknownHostTimeIsRefusedBeforeTheGraphRuns) {
  record(1);
  EXPECT_EQ(start_error(replay_graph(folder_, {{"host_time", "live"}})),
            (dir_.path() / "graph.json").string() +
                ":/nodes/src/params/host_time: parameter 'host_time': expected one of "
                "'replayed', 'recorded', got \"live\"");
}

// A writer killed between a frame's two lines leaves one line more in
// host_timestamps.csv than in frames.csv: it is ignored.
TEST_F(ImageFolderSourceTest, AHostTimeAfterTheLastFrameIsIgnored) {
  record(3);  // indices 3, 4, 6
  write_host_timestamps(folder_, frames_);
  write_text(folder_ / "host_timestamps.csv",
             read_text(folder_ / "host_timestamps.csv") + "7,1763800000302000000\n");
  const RunResult result = run(replay_graph(folder_, {{"host_time", "recorded"}}));
  ASSERT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3, 4, 6}));
  EXPECT_EQ(captured_.back().info.host_timestamp_ns, frames_.back().host_timestamp_ns);
}

TEST_F(ImageFolderSourceTest, HostTimestampsCsvErrorsNameTheLineAndWhatWasExpected) {
  record(3);  // indices 3, 4, 6 on frames.csv lines 2, 3, 4
  const auto with_host_csv = [&](const std::string& text) {
    write_text(folder_ / "host_timestamps.csv", text);
    return start_failure();
  };
  const std::string header = "index,host_timestamp_ns\n";
  EXPECT_EQ(with_host_csv(""),
            host_csv() + ":1: expected the header 'index,host_timestamp_ns', got an empty file");
  EXPECT_EQ(with_host_csv("index,host_ns\n3,1\n4,2\n6,3\n"),
            host_csv() + ":1: expected the header 'index,host_timestamp_ns', got 'index,host_ns'");
  EXPECT_EQ(with_host_csv(header + "3,1\n4,2,7\n6,3\n"),
            host_csv() + ":3: expected 2 fields (index,host_timestamp_ns), got '4,2,7'");
  EXPECT_EQ(with_host_csv(header + "3,1\n4\n6,3\n"),
            host_csv() + ":3: expected 2 fields (index,host_timestamp_ns), got '4'");
  EXPECT_EQ(with_host_csv(header + "3,1\nfour,2\n6,3\n"),
            host_csv() + ":3: column 'index': expected a non-negative integer, got 'four'");
  EXPECT_EQ(with_host_csv(header + "3,1\n4,17638OO000\n6,3\n"),
            host_csv() +
                ":3: column 'host_timestamp_ns': expected a non-negative integer number of "
                "nanoseconds, got '17638OO000'");
  EXPECT_EQ(with_host_csv(header + "3,1\n4,-2\n6,3\n"),
            host_csv() +
                ":3: column 'host_timestamp_ns': expected a non-negative integer number of "
                "nanoseconds, got '-2'");
  EXPECT_EQ(with_host_csv(header + "3,1\n\n6,3\n4,2\n"),
            host_csv() + ":4: column 'index': expected 4, the index on frames.csv line 3, got '6'");
  EXPECT_EQ(with_host_csv(header + "3,1\n4,2\n"),
            host_csv() +
                ": ends after 2 frames; expected a line for each of the 3 frames of frames.csv, "
                "the next for index 6 (frames.csv line 4)");
  EXPECT_EQ(with_host_csv(header + "3,1\n4,2\n6,3\n5,4\n"),
            host_csv() +
                ":5: column 'index': expected a value > 6 (the last frame, frames.csv line 4), "
                "got '5'");
  EXPECT_EQ(with_host_csv(header + "3,1\n4,2\n6,3\n7,4\n8,5\n"),
            host_csv() +
                ":6: expected at most one line after the last frame of frames.csv (one a killed "
                "writer wrote), got a second");
}

// Wrong images stop the stream: the run fails after the frames before it.
TEST_F(ImageFolderSourceTest, WrongBitDepthSizeOrChannelsStopTheStream) {
  const std::string prefix = "node 'src' (recording.image_folder) failed: ";
  const std::string suffix = "; its stream ends here";
  struct Case {
    std::string file;
    cv::Mat image;
    std::string expected;
  };
  const std::vector<Case> cases{
      {"depth/000004.png", cv::Mat(24, 32, CV_8UC1, cv::Scalar(9)),
       "expected 16-bit 1-channel, 32x24 pixels (depth_camera in the calibration), got 8-bit "
       "1-channel, 32x24 pixels"},
      {"depth/000004.png", cv::Mat(12, 16, CV_16UC1, cv::Scalar(9)),
       "expected 16-bit 1-channel, 32x24 pixels (depth_camera in the calibration), got 16-bit "
       "1-channel, 16x12 pixels"},
      {"color/000004.png", cv::Mat(30, 40, CV_8UC1, cv::Scalar(9)),
       "expected 8-bit 3-channel, 40x30 pixels (color_camera in the calibration), got 8-bit "
       "1-channel, 40x30 pixels"},
      {"color/000004.png", cv::Mat(30, 40, CV_16UC3, cv::Scalar(9, 9, 9)),
       "expected 8-bit 3-channel, 40x30 pixels (color_camera in the calibration), got 16-bit "
       "3-channel, 40x30 pixels"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.expected);
    captured_.clear();
    record(3);
    ASSERT_TRUE(cv::imwrite((folder_ / c.file).string(), c.image));
    const RunResult result = run(replay_graph(folder_));
    EXPECT_TRUE(result.failed);
    EXPECT_EQ(result.failure, prefix + (folder_ / c.file).string() +
                                  " (frames.csv line 3): " + c.expected + suffix);
    EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3}));
  }

  captured_.clear();
  record(3);  // frame 6 (line 4) has a mask
  ASSERT_TRUE(cv::imwrite((folder_ / "mask/000006.png").string(),
                          cv::Mat(24, 32, CV_16UC1, cv::Scalar(0))));
  const RunResult result = run(replay_graph(folder_));
  EXPECT_EQ(result.failure, prefix + (folder_ / "mask/000006.png").string() +
                                " (frames.csv line 4): expected 8-bit 1-channel, 32x24 pixels "
                                "(depth_camera in the calibration), got 16-bit 1-channel, 32x24 "
                                "pixels" +
                                suffix);
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3, 4}));
}

TEST_F(ImageFolderSourceTest, MissingOrUnreadablePngSkipsTheFrameWithAWarning) {
  record(5);
  fs::remove(folder_ / "color/000006.png");
  write_text(folder_ / "depth/000008.png", "not a PNG");
  // Cut before its last chunk, as a copy that stopped part way leaves a file.
  const fs::path cut = folder_ / "color/000007.png";
  const std::uintmax_t cut_size = fs::file_size(cut) - 12;
  fs::resize_file(cut, cut_size);
  const RunResult result = run(replay_graph(folder_, {{"on_missing", "skip"}}));
  EXPECT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3, 4}));
  EXPECT_EQ(result.metrics.frames_completed, 2u);
  const auto logged = warnings();
  const std::vector<std::string> expected{
      "src: " + (folder_ / "color/000006.png").string() +
          " (frames.csv line 4): no such file; frame 6 skipped (on_missing: skip)",
      "src: " + cut.string() +
          " (frames.csv line 5): damaged PNG: the file ends inside a chunk's header "
          "(truncated?) at byte " +
          std::to_string(cut_size) + "; frame 7 skipped (on_missing: skip)",
      "src: " + (folder_ / "depth/000008.png").string() +
          " (frames.csv line 6): not a readable image; frame 8 skipped (on_missing: skip)"};
  EXPECT_EQ(logged, expected);
}

// Decoded up to 8 frames ahead on threads of their own, the frames, their warnings and
// a failure still come in the recording's order.
TEST_F(ImageFolderSourceTest, FramesDecodedAheadComeInTheRecordingsOrder) {
  record(12, 1'000'000);
  fs::remove(folder_ / "color/000006.png");
  const RunResult result = run(replay_graph(folder_, {{"decode_ahead", 8}}));
  ASSERT_FALSE(result.failed) << result.failure;
  std::vector<std::uint64_t> expected_ids;
  for (const TestFrame& frame : frames_) {
    if (frame.index != 6) expected_ids.push_back(frame.index);
  }
  ASSERT_EQ(captured_ids(), expected_ids);
  for (std::size_t i = 0, frame = 0; i < captured_.size(); ++i, ++frame) {
    if (frames_[frame].index == 6) ++frame;
    EXPECT_TRUE(same_pixels(frames_[frame].depth, captured_[i].raw->gray)) << "frame " << i;
    EXPECT_TRUE(same_pixels(frames_[frame].color, captured_[i].color->pixels)) << "frame " << i;
  }
  EXPECT_EQ(
      warnings(),
      (std::vector<std::string>{"src: " + (folder_ / "color/000006.png").string() +
                                " (frames.csv line 4): no such file; frame 6 skipped (on_missing: "
                                "skip)"}));

  write_text(folder_ / "depth/000008.png", "not a PNG");
  const RunResult stopped =
      run(replay_graph(folder_, {{"decode_ahead", 8}, {"on_missing", "stop"}}));
  EXPECT_TRUE(stopped.failed);
  EXPECT_EQ(stopped.failure, "node 'src' (recording.image_folder) failed: " +
                                 (folder_ / "color/000006.png").string() +
                                 " (frames.csv line 4): no such file (on_missing: stop); its "
                                 "stream ends here");
}

TEST_F(ImageFolderSourceTest, MissingPngStopsWhenAsked) {
  record(5);
  fs::remove(folder_ / "color/000006.png");
  const RunResult result = run(replay_graph(folder_, {{"on_missing", "stop"}}));
  EXPECT_TRUE(result.failed);
  EXPECT_EQ(result.failure, "node 'src' (recording.image_folder) failed: " +
                                (folder_ / "color/000006.png").string() +
                                " (frames.csv line 4): no such file (on_missing: stop); its "
                                "stream ends here");
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3, 4}));
}

// A FIFO (or a device) named by a recording blocked the replay for good, and SIGTERM
// did not end it: only regular files are read.
TEST_F(ImageFolderSourceTest, AFifoOrDeviceInTheRecordingIsRefusedNotWaitedFor) {
  record(3);
  {
    const Fifo fifo(folder_ / "depth/000004.png");
    const auto start = Clock::now();
    const RunResult result = run(replay_graph(folder_, {{"on_missing", "stop"}}));
    EXPECT_LT(seconds_since(start), 2.0);
    EXPECT_EQ(result.failure, "node 'src' (recording.image_folder) failed: " +
                                  (folder_ / "depth/000004.png").string() +
                                  " (frames.csv line 3): is a FIFO; expected a regular file (PNG "
                                  "image) (on_missing: stop); its stream ends here");
    EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3}));
  }
  record(3);
  for (const std::string name : {"frames.csv", "host_timestamps.csv", "recording.json"}) {
    SCOPED_TRACE(name);
    write_host_timestamps(folder_, frames_);
    const std::string what = name == "recording.json" ? "recording.json" : name;
    {
      const Fifo fifo(folder_ / name);
      const auto start = Clock::now();
      EXPECT_EQ(start_failure(),
                (folder_ / name).string() + ": is a FIFO; expected a regular file (" + what + ")");
      EXPECT_LT(seconds_since(start), 2.0);
    }
    record(3);
  }
  fs::remove(folder_ / "frames.csv");
  fs::create_symlink("/dev/null", folder_ / "frames.csv");
  EXPECT_EQ(start_failure(),
            csv() + ": is a character device; expected a regular file (frames.csv)");
}

TEST_F(ImageFolderSourceTest, FramesCsvBeyondItsLimitsIsALocatedError) {
  record(3);
  replace_line(3, "4,1100000000,1100400000,depth/" + std::string(20'000, 'x') + ".png,c,,");
  EXPECT_EQ(start_failure(), csv() + ":3: a line of 20038 bytes; expected at most 16384");

  record(3);
  replace_line(3, "99999999999999999999,1100000000,1100400000,depth/000004.png,c,,");
  EXPECT_EQ(start_failure(), csv() +
                                 ":3: column 'index': expected a non-negative integer from 0 to "
                                 "18446744073709551615, got '99999999999999999999'");
  replace_line(3, "4,9223372036854775808,1100400000,depth/000004.png,c,,");
  EXPECT_EQ(start_failure(), csv() +
                                 ":3: column 'depth_timestamp_ns': expected an integer number of "
                                 "nanoseconds from -9223372036854775808 to 9223372036854775807, "
                                 "got '9223372036854775808'");

  // Sparse: no disk is used.
  record(3);
  fs::resize_file(folder_ / "frames.csv", (128u << 20) + 1);
  EXPECT_EQ(start_failure(), csv() +
                                 ": is 134217729 bytes; expected at most 134217728 for a "
                                 "frames.csv");

  std::string lines(kFramesHeader);
  lines += "\n";
  for (int i = 0; i <= 1'000'000; ++i) {
    const std::string n = std::to_string(i);
    lines.append(n).append(",").append(n).append(",").append(n).append(",d,c,,\n");
  }
  write_text(folder_ / "frames.csv", lines);
  EXPECT_EQ(start_failure(),
            csv() + ":1000002: more than 1000000 frames; expected at most that many");
}

// 10 frames 100 ms apart span 0.9 s of recorded time.
TEST_F(ImageFolderSourceTest, RateOnePacesByTheDepthTimestamps) {
  record(10);
  const auto start = Clock::now();
  const RunResult result = run(replay_graph(folder_, {{"rate", 1}}));
  EXPECT_GE(seconds_since(start), 0.9);
  EXPECT_EQ(result.metrics.frames_completed, 10u);
}

// 10 frames 200 ms apart: 1.8 s recorded, 0.9 s at twice the speed.
TEST_F(ImageFolderSourceTest, RateTwoPacesTwiceAsFast) {
  record(10, 200'000'000);
  const auto start = Clock::now();
  run(replay_graph(folder_, {{"rate", 2}}));
  const double elapsed = seconds_since(start);
  EXPECT_GE(elapsed, 0.9);
  EXPECT_LT(elapsed, 1.7);
  EXPECT_EQ(captured_.size(), 10u);
}

TEST_F(ImageFolderSourceTest, RateZeroDoesNotWait) {
  record(10, 1'000'000'000);  // 9 s of recorded time
  const auto start = Clock::now();
  run(replay_graph(folder_, {{"rate", 0}}));
  EXPECT_LT(seconds_since(start), 4.5);
  EXPECT_EQ(captured_.size(), 10u);
}

TEST_F(ImageFolderSourceTest, StopInterruptsAPacedWait) {
  record(3, 60'000'000'000);  // a minute between frames
  auto runtime = make(replay_graph(folder_, {{"rate", 1}}));
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    runtime->stop();
  });
  const auto start = Clock::now();
  const RunResult result = runtime->run();
  stopper.join();
  EXPECT_LT(seconds_since(start), 5.0);
  EXPECT_FALSE(result.failed);
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3}));
}

TEST_F(ImageFolderSourceTest, LoopStartsAgainAfterTheLastFrame) {
  record(3);
  run(replay_graph(folder_, {{"loop", true}}), RunLimits{8});
  EXPECT_EQ(captured_ids(), (std::vector<std::uint64_t>{3, 4, 6, 3, 4, 6, 3, 4}));
  EXPECT_TRUE(same_pixels(frames_[1].depth, captured_[7].raw->gray));
}

TEST_F(ImageFolderSourceTest, LoopEndsWhenNoFrameCanBeRead) {
  record(2);
  fs::remove(folder_ / "depth/000003.png");
  fs::remove(folder_ / "depth/000004.png");
  const RunResult result = run(replay_graph(folder_, {{"loop", true}}));
  EXPECT_FALSE(result.failed);
  EXPECT_TRUE(captured_.empty());
  ASSERT_EQ(warnings().size(), 3u);
  EXPECT_EQ(warnings().back(),
            "src: " + folder_.string() + ": no frame of the recording could be read; not looping");
}

}  // namespace
}  // namespace tilth::testing
