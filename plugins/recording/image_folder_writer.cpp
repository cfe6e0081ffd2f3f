// Writes frames as an image-folder recording (spec: tilth-image-folder/1) that
// recording.image_folder replays, with each frame's host capture time in
// host_timestamps.csv. Every frame is checked against what the reader accepts before any
// of its files is written, and its lines are appended and flushed only after its PNGs
// are complete, host_timestamps.csv's before frames.csv's: a killed process leaves a
// valid recording that lacks at most the frame being written. Colour images that are a
// window of the sensor (a camera's region of interest) are recorded with that window in
// recording.json (RecordedColorWindow).
#include <array>
#include <fstream>
#include <optional>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "color_window/recorded_color_window.h"
#include "image_folder/frames_csv.h"
#include "image_folder/host_timestamps_csv.h"
#include "image_folder/pixel_checks.h"
#include "image_folder/recording_json.h"
#include "tilth/calibration.h"
#include "tilth/json_input.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace tilth::recording {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kRawPort = 0;
constexpr std::size_t kColorPort = 1;
constexpr std::size_t kTruthPort = 2;
constexpr std::string_view kCalibrationFile = "rig.calib.json";
// What replacing a recording removes; anything else in the folder stays.
constexpr std::array<std::string_view, 7> kRecordingEntries{
    "recording.json", "frames.csv", kHostTimestampsFile, kCalibrationFile, "depth",
    "color",          "mask"};

// Throws unless the folder can be written: it does not exist, is empty, or holds a
// recording that `overwrite` allows to replace. Changes nothing, so a graph that fails to
// start leaves the folder as it was.
void check_folder(const fs::path& folder, bool overwrite) {
  if (!fs::exists(folder)) return;
  if (!fs::is_directory(folder)) throw Error(folder.string() + ": exists and is not a folder");
  if (fs::is_empty(folder)) return;
  if (!overwrite) {
    throw Error(folder.string() +
                ": folder exists and is not empty; set overwrite: true to replace the "
                "recording in it");
  }
  if (!fs::exists(folder / "recording.json")) {
    throw Error(folder.string() +
                ": folder is not empty and holds no recording.json; not overwriting a folder "
                "that is not a recording");
  }
}

struct StoredColor {
  PixelFormat format;
  cv::Mat pixels;
};

void write_png(const fs::path& file, const cv::Mat& image) {
  if (!cv::imwrite(file.string(), image)) throw Error(file.string() + ": cannot write PNG");
}

// The frame's host capture time, or its depth device time when the host's is unknown
// (0), as mcap.writer records it.
std::int64_t recorded_host_time(const FrameInfo& info, std::int64_t depth_timestamp_ns) {
  if (info.host_timestamp_ns < 0) {
    throw Error("host timestamp " + std::to_string(info.host_timestamp_ns) +
                " ns; expected >= 0 (CLOCK_REALTIME)");
  }
  return info.host_timestamp_ns != 0 ? info.host_timestamp_ns : depth_timestamp_ns;
}

// Appends a line and flushes it.
void append_line(std::ofstream& out, const std::string& line, const fs::path& file) {
  out << line << "\n" << std::flush;
  if (!out) throw Error(file.string() + ": cannot write");
}

void close_file(std::ofstream& out, const fs::path& file) {
  out.close();
  if (!out) throw Error(file.string() + ": cannot write");
}

class ImageFolderWriter final : public Sink {
 public:
  explicit ImageFolderWriter(const StageContext& context)
      : folder_(context.params.path("path")),
        calibration_(load_calibration(context.params.path("calibration"))),
        // Kept, not copied later: the file may be in the folder that overwrite replaces.
        calibration_text_(read_json_text(context.params.path("calibration"), "calibration file")),
        description_(context.params.string("description")),
        depth_size_(calibration_.depth.width, calibration_.depth.height),
        color_window_(calibration_.color) {
    check_folder(folder_, context.params.boolean("overwrite"));
  }

  void consume(const Frame& frame) override {
    const auto& raw = frame.input<RawTofFrame>(kRawPort);
    const auto& color = frame.input<ColorImage>(kColorPort);
    const Packet& truth_packet = frame.input(kTruthPort);
    const GroundTruth* truth = truth_packet.empty() ? nullptr : &truth_packet.get<GroundTruth>();

    FrameEntry entry;
    entry.index = frame.info().frame_id;
    entry.depth_timestamp_ns = raw.device_timestamp_ns;
    entry.color_timestamp_ns = color.device_timestamp_ns;
    entry.depth = "depth/" + frame_file_name(entry.index);
    entry.color = "color/" + frame_file_name(entry.index);
    if (truth != nullptr && !truth->residue_mask.empty()) {
      entry.mask = "mask/" + frame_file_name(entry.index);
    }
    if (truth != nullptr) entry.ground_truth_mm = truth->distance_mm;
    const std::int64_t host_time = recorded_host_time(frame.info(), entry.depth_timestamp_ns);
    check_order(entry);
    check("raw",
          pixel_mismatch(raw.gray, CV_16UC1, depth_size_, "depth_camera in the calibration"));
    const cv::Rect window = color_window_.check(color);
    const StoredColor stored = stored_color(color, window.size());
    if (!entry.mask.empty()) {
      check("truth mask", pixel_mismatch(truth->residue_mask, CV_8UC1, depth_size_,
                                         "depth_camera in the calibration"));
    }

    if (!color_format_) start(stored.format, window);
    write_png(folder_ / entry.depth, raw.gray);
    write_png(folder_ / entry.color, stored.pixels);
    if (!entry.mask.empty()) {
      fs::create_directories(folder_ / "mask");
      write_png(folder_ / entry.mask, truth->residue_mask);
    }
    append_line(host_csv_, host_timestamps_line(entry.index, host_time),
                folder_ / kHostTimestampsFile);
    append_line(csv_, frames_csv_line(entry), folder_ / "frames.csv");
    previous_ = entry;
  }

  void finish() override {
    // A recording without frames is still a valid, empty one.
    if (!color_format_) start(PixelFormat::kBgr8, std::nullopt);
    close_file(csv_, folder_ / "frames.csv");
    close_file(host_csv_, folder_ / kHostTimestampsFile);
  }

 private:
  // Replaces the old recording, if any, with an empty one in `color_format` whose colour
  // images are `window` of the sensor (none: the whole image). Runs with the first frame
  // to write, so a graph that does not run changes nothing.
  void start(PixelFormat color_format, const std::optional<cv::Rect>& window) {
    if (window) color_window_.take(*window);
    for (std::string_view entry : kRecordingEntries) fs::remove_all(folder_ / entry);
    fs::create_directories(folder_ / "depth");
    fs::create_directories(folder_ / "color");
    write_recording_json(folder_, std::string(kCalibrationFile), color_format, description_,
                         color_window_.stored());
    std::ofstream calibration(folder_ / kCalibrationFile, std::ios::binary);
    calibration << calibration_text_;
    if (!calibration) throw Error((folder_ / kCalibrationFile).string() + ": cannot write");
    host_csv_.open(folder_ / kHostTimestampsFile);
    append_line(host_csv_, std::string(kHostTimestampsHeader), folder_ / kHostTimestampsFile);
    csv_.open(folder_ / "frames.csv");
    append_line(csv_, std::string(kFramesCsvHeader), folder_ / "frames.csv");
    color_format_ = color_format;
  }

  static void check(std::string_view port, const std::string& mismatch) {
    if (!mismatch.empty()) throw Error(std::string(port) + ": " + mismatch);
  }

  // The reader refuses indices and timestamps that do not increase.
  void check_order(const FrameEntry& entry) const {
    if (!previous_) return;
    const auto expect_after = [](std::string_view what, auto previous, auto current) {
      if (current <= previous) {
        throw Error(std::string(what) + ": expected a value > " + std::to_string(previous) +
                    " (the previous frame's), got " + std::to_string(current));
      }
    };
    expect_after("frame id", previous_->index, entry.index);
    expect_after("raw device timestamp", previous_->depth_timestamp_ns, entry.depth_timestamp_ns);
    expect_after("color device timestamp", previous_->color_timestamp_ns, entry.color_timestamp_ns);
  }

  // The colour image as the recording stores it: rgb8 becomes bgr8, and the format must
  // be the one of the first frame.
  StoredColor stored_color(const ColorImage& color, cv::Size window) const {
    const PixelFormat format =
        color.format == PixelFormat::kRgb8 ? PixelFormat::kBgr8 : color.format;
    if (!is_recording_color_format(format)) {
      throw Error("color: " + std::string(to_string(color.format)) +
                  " cannot be recorded; expected bgr8, rgb8 (stored as bgr8) or a Bayer mosaic");
    }
    if (color_format_ && format != *color_format_) {
      throw Error("color: expected " + std::string(to_string(*color_format_)) +
                  " as in the first frame (a recording has one color_format), got " +
                  std::string(to_string(color.format)));
    }
    // A window's size is its image's: only a whole image can mismatch.
    check("color", pixel_mismatch(color.pixels, CV_8UC(channels(format)), window,
                                  "color_camera in the calibration"));
    if (color.format != PixelFormat::kRgb8) return {format, color.pixels};
    cv::Mat bgr;
    cv::cvtColor(color.pixels, bgr, cv::COLOR_RGB2BGR);
    return {format, bgr};
  }

  const fs::path folder_;
  const RigCalibration calibration_;
  const std::string calibration_text_;
  const std::string description_;
  const cv::Size depth_size_;
  RecordedColorWindow color_window_;
  std::ofstream csv_;                        // frames.csv
  std::ofstream host_csv_;                   // host_timestamps.csv
  std::optional<PixelFormat> color_format_;  // set by start(), from the first written frame
  std::optional<FrameEntry> previous_;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "recording.image_folder_writer";
  d.summary =
      "writes frames as an image-folder recording (PNG files, frames.csv and "
      "host_timestamps.csv)";
  d.inputs = {
      PortSpec::of<RawTofFrame>("raw", "16-bit ToF gray, the calibration's depth_camera size"),
      PortSpec::of<ColorImage>("color",
                               "bgr8, rgb8 (stored as bgr8) or a Bayer mosaic; the calibration's "
                               "size, or one window of the sensor (ColorImage::sensor_offset)"),
      PortSpec::of<GroundTruth>("truth", "ground truth distance and mask, when known").optional(),
  };
  d.params = {
      ParamSpec::output_path("path", std::nullopt).describe("the recording folder to create"),
      ParamSpec::path("calibration", std::nullopt)
          .describe("the rig's calibration file; copied into the folder as rig.calib.json"),
      ParamSpec::boolean("overwrite", false)
          .describe("replace the recording in an existing, non-empty folder"),
      ParamSpec::string("description", "").describe("free text for recording.json"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<ImageFolderWriter>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::recording
