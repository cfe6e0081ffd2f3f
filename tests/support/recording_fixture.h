// What the recording tests share: recordings written by the test's own code (cv::imwrite
// and plain text, not the plugin's), the built recording plugin in a registry next to
// an in-process source that feeds chosen messages and a sink that keeps what it gets,
// and running a graph through the real runtime.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "framework/runtime.h"
#include "framework/stage_registry.h"
#include "temp_dir.h"
#include "tilth/log.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"

namespace tilth::testing {

namespace fs = std::filesystem;

// One frame as the tests know it.
struct TestFrame {
  std::uint64_t index = 0;
  std::int64_t depth_timestamp_ns = 0;
  std::int64_t color_timestamp_ns = 0;
  std::int64_t host_timestamp_ns = 0;  // CLOCK_REALTIME
  cv::Mat depth;                       // CV_16UC1
  cv::Mat color;                       // CV_8UC3 (bgr8) or CV_8UC1 (Bayer)
  cv::Mat mask;                        // CV_8UC1 of 0, 128, 255; empty: none
  std::optional<double> ground_truth_mm;
};

// The paper rig as shipped (calib/paper_rig.calib.json).
fs::path shipped_calibration_file();
// The paper rig with small images (depth 32x24, colour 40x30), so tests stay fast.
nlohmann::json small_calibration();

// `count` frames of random pixels in the calibration's sizes: indices from 3 with a gap,
// depth frames 100 ms apart, colour 0.4 ms after depth, host capture times as far apart
// on a wall clock in November 2025; every second frame has a mask and a ground truth.
// Depth includes 0 and 65535.
std::vector<TestFrame> make_frames(int count, const nlohmann::json& calibration, int color_channels,
                                   std::int64_t spacing_ns = 100'000'000);

// Writes a recording folder following the spec: PNGs, frames.csv with every column,
// recording.json with `calibration` as given (an object, or a file name in the folder).
void write_recording(const fs::path& folder, const std::vector<TestFrame>& frames,
                     const std::string& color_format, const nlohmann::json& calibration);
// Adds the frames' host capture times as host_timestamps.csv, the Tilth extension.
void write_host_timestamps(const fs::path& folder, const std::vector<TestFrame>& frames);

// "depth/000003.png": the file name the spec's example and the writer use.
std::string frame_file(const std::string& folder, std::uint64_t index);
std::string read_text(const fs::path& file);
void write_text(const fs::path& file, const std::string& text);
// Same type, size and every pixel.
::testing::AssertionResult same_pixels(const cv::Mat& expected, const cv::Mat& actual);

// What the capture sink received for one frame.
struct Captured {
  FrameInfo info;
  std::shared_ptr<const RawTofFrame> raw;
  std::shared_ptr<const ColorImage> color;
  std::shared_ptr<const GroundTruth> truth;  // null when its input had no data
};

// What the feed source emits for one frame; no truth leaves that output unset.
struct Feed {
  std::uint64_t frame_id = 0;
  std::int64_t host_timestamp_ns = 0;  // 0: the runtime stamps the frame as it enters
  RawTofFrame raw;
  ColorImage color;
  std::optional<GroundTruth> truth;
};

class RecordingTest : public ::testing::Test {
 protected:
  // Loads the plugin and adds `test.feed` (source: raw, color, truth from feed_) and
  // `test.capture` (sink: raw, color, optional truth, into captured_).
  RecordingTest();
  ~RecordingTest() override;

  // Validates the graph and makes its stages; throws as Runtime does.
  std::unique_ptr<Runtime> make(const std::string& graph, RunLimits limits = {});
  RunResult run(const std::string& graph, RunLimits limits = {});
  // The message of the tilth::Error that making the graph's stages throws, or "".
  std::string start_error(const std::string& graph);

  std::vector<std::uint64_t> captured_ids() const;
  std::vector<std::string> warnings() const;

  TempDir dir_;
  StageRegistry registry_;
  std::vector<Feed> feed_;
  std::vector<Captured> captured_;

 private:
  mutable std::mutex log_mutex_;
  std::vector<std::string> warnings_;
  LogHandler previous_handler_;
};

}  // namespace tilth::testing
