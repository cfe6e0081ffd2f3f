#include "recording_fixture.h"

#include <cstdio>
#include <fstream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "framework/graph_loader.h"
#include "source_tree.h"
#include "tilth/plugin.h"

namespace tilth::testing {
namespace {

class FeedSource final : public Source {
 public:
  FeedSource(const std::vector<Feed>& feed) : feed_(feed) {}
  bool produce(Frame& frame) override {
    if (next_ == feed_.size()) return false;
    const Feed& feed = feed_[next_++];
    frame.set_capture(feed.frame_id, feed.raw.device_timestamp_ns, feed.host_timestamp_ns);
    frame.emit(0, feed.raw);
    frame.emit(1, feed.color);
    if (feed.truth) frame.emit(2, *feed.truth);
    return true;
  }

 private:
  const std::vector<Feed>& feed_;
  std::size_t next_ = 0;
};

class CaptureSink final : public Sink {
 public:
  explicit CaptureSink(std::vector<Captured>& captured) : captured_(captured) {}
  void consume(const Frame& frame) override {
    Captured captured;
    captured.info = frame.info();
    captured.raw = frame.share_input<RawTofFrame>(0);
    captured.color = frame.share_input<ColorImage>(1);
    if (!frame.input(2).empty()) captured.truth = frame.share_input<GroundTruth>(2);
    captured_.push_back(std::move(captured));
  }

 private:
  std::vector<Captured>& captured_;
};

}  // namespace

std::string frame_file(const std::string& folder, std::uint64_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "%06llu.png", static_cast<unsigned long long>(index));
  return folder + "/" + name;
}

fs::path shipped_calibration_file() { return paper_rig_path(); }

nlohmann::json small_calibration() {
  nlohmann::json calibration = nlohmann::json::parse(read_text(shipped_calibration_file()));
  // The principal points move with the sizes: a calibration's must lie inside its image.
  calibration["depth_camera"]["width"] = 32;
  calibration["depth_camera"]["height"] = 24;
  calibration["depth_camera"]["cx"] = 15.5;
  calibration["depth_camera"]["cy"] = 11.5;
  calibration["color_camera"]["width"] = 40;
  calibration["color_camera"]["height"] = 30;
  calibration["color_camera"]["cx"] = 19.5;
  calibration["color_camera"]["cy"] = 14.5;
  return calibration;
}

std::vector<TestFrame> make_frames(int count, const nlohmann::json& calibration, int color_channels,
                                   std::int64_t spacing_ns) {
  const cv::Size depth_size(calibration["depth_camera"]["width"].get<int>(),
                            calibration["depth_camera"]["height"].get<int>());
  const cv::Size color_size(calibration["color_camera"]["width"].get<int>(),
                            calibration["color_camera"]["height"].get<int>());
  cv::RNG random(42);
  std::vector<TestFrame> frames;
  for (int i = 0; i < count; ++i) {
    TestFrame frame;
    frame.index = 3 + static_cast<std::uint64_t>(i) + (i >= 2 ? 1 : 0);
    frame.depth_timestamp_ns = 1'000'000'000 + i * spacing_ns;
    frame.color_timestamp_ns = frame.depth_timestamp_ns + 400'000;
    frame.host_timestamp_ns = 1'763'800'000'002'000'000 + i * spacing_ns;
    frame.depth.create(depth_size, CV_16UC1);
    random.fill(frame.depth, cv::RNG::UNIFORM, 0, 65536);
    frame.depth.at<std::uint16_t>(0, 0) = 0;
    frame.depth.at<std::uint16_t>(0, 1) = 65535;
    frame.color.create(color_size, CV_8UC(color_channels));
    random.fill(frame.color, cv::RNG::UNIFORM, 0, 256);
    if (i % 2 == 0) {
      cv::Mat choice(depth_size, CV_8UC1);
      random.fill(choice, cv::RNG::UNIFORM, 0, 3);
      frame.mask = cv::Mat::zeros(depth_size, CV_8UC1);
      frame.mask.setTo(128, choice == 1);
      frame.mask.setTo(255, choice == 2);
      frame.ground_truth_mm = 500.0 + 0.25 * i;
    }
    frames.push_back(std::move(frame));
  }
  return frames;
}

void write_recording(const fs::path& folder, const std::vector<TestFrame>& frames,
                     const std::string& color_format, const nlohmann::json& calibration) {
  fs::create_directories(folder / "depth");
  fs::create_directories(folder / "color");
  fs::create_directories(folder / "mask");
  std::ostringstream csv;
  csv << "index,depth_timestamp_ns,color_timestamp_ns,depth,color,mask,ground_truth_mm\n";
  for (const auto& frame : frames) {
    const std::string depth = frame_file("depth", frame.index);
    const std::string color = frame_file("color", frame.index);
    const std::string mask = frame.mask.empty() ? "" : frame_file("mask", frame.index);
    EXPECT_TRUE(cv::imwrite((folder / depth).string(), frame.depth));
    EXPECT_TRUE(cv::imwrite((folder / color).string(), frame.color));
    if (!mask.empty()) {
      EXPECT_TRUE(cv::imwrite((folder / mask).string(), frame.mask));
    }
    csv << frame.index << "," << frame.depth_timestamp_ns << "," << frame.color_timestamp_ns << ","
        << depth << "," << color << "," << mask << ",";
    if (frame.ground_truth_mm) csv << *frame.ground_truth_mm;
    csv << "\n";
  }
  write_text(folder / "frames.csv", csv.str());
  const nlohmann::json recording = {{"format", "tilth-image-folder/1"},
                                    {"calibration", calibration},
                                    {"color_format", color_format},
                                    {"description", "test recording"}};
  write_text(folder / "recording.json", recording.dump(2));
}

void write_host_timestamps(const fs::path& folder, const std::vector<TestFrame>& frames) {
  std::ostringstream csv;
  csv << "index,host_timestamp_ns\n";
  for (const auto& frame : frames) csv << frame.index << "," << frame.host_timestamp_ns << "\n";
  write_text(folder / "host_timestamps.csv", csv.str());
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

void write_text(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

::testing::AssertionResult same_pixels(const cv::Mat& expected, const cv::Mat& actual) {
  if (expected.type() != actual.type() || expected.size() != actual.size()) {
    return ::testing::AssertionFailure()
           << "expected type " << expected.type() << " " << expected.size() << ", got type "
           << actual.type() << " " << actual.size();
  }
  const double difference = cv::norm(expected, actual, cv::NORM_INF);
  if (difference != 0.0) {
    return ::testing::AssertionFailure() << "pixels differ by up to " << difference;
  }
  return ::testing::AssertionSuccess();
}

RecordingTest::RecordingTest() {
  registry_.load(TILTH_RECORDING_PLUGIN);

  StageDescriptor feed;
  feed.type = "test.feed";
  feed.outputs = {PortSpec::of<RawTofFrame>("raw", ""), PortSpec::of<ColorImage>("color", ""),
                  PortSpec::of<GroundTruth>("truth", "")};
  feed.create = [this](const StageContext&) { return std::make_unique<FeedSource>(feed_); };
  registry_.add(std::move(feed), "recording tests");

  StageDescriptor capture;
  capture.type = "test.capture";
  capture.inputs = {PortSpec::of<RawTofFrame>("raw", ""), PortSpec::of<ColorImage>("color", ""),
                    PortSpec::of<GroundTruth>("truth", "").optional()};
  capture.create = [this](const StageContext&) { return std::make_unique<CaptureSink>(captured_); };
  registry_.add(std::move(capture), "recording tests");

  previous_handler_ =
      set_log_handler([this](LogLevel level, std::string_view where, std::string_view message) {
        if (level != LogLevel::kWarning) return;
        std::lock_guard lock(log_mutex_);
        warnings_.push_back(std::string(where) + ": " + std::string(message));
      });
}

RecordingTest::~RecordingTest() { set_log_handler(previous_handler_); }

std::unique_ptr<Runtime> RecordingTest::make(const std::string& graph, RunLimits limits) {
  const fs::path file = dir_.write("graph.json", graph);
  return std::make_unique<Runtime>(validate_graph(load_graph(file), registry_), registry_, limits);
}

RunResult RecordingTest::run(const std::string& graph, RunLimits limits) {
  return make(graph, limits)->run();
}

std::string RecordingTest::start_error(const std::string& graph) {
  try {
    make(graph);
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

std::vector<std::uint64_t> RecordingTest::captured_ids() const {
  std::vector<std::uint64_t> ids;
  for (const auto& captured : captured_) ids.push_back(captured.info.frame_id);
  return ids;
}

std::vector<std::string> RecordingTest::warnings() const {
  std::lock_guard lock(log_mutex_);
  return warnings_;
}

}  // namespace tilth::testing
