// mcap.writer: records raw ToF frames, colour images and ground truth as an MCAP file
// that mcap.player replays and Foxglove opens as it is.
//
//   raw ──┐
//   color ├─> mcap.writer ──> FILE.mcap: /tof/raw, /color/image, /truth, /truth/mask
//   truth ┘   (optional)
//
// Invariant: a frame's messages are never split across chunks (a chunk is closed only
// between frames), so a file cut off mid-write loses whole frames, never half of one.
//
// A write that fails (a full disk) stops the recording, not the graph: the file keeps
// the chunks written before it, without a summary (`tilth recording repair` adds one),
// and every frame not stored is reported as lost data.
//
// As in a ROS 2 bag, a message's log (and publish) time is when the frame was captured
// on the host's clock, so Foxglove shows wall-clock dates; each image's own timestamp
// is its device time.
#include <chrono>
#include <deque>
#include <functional>
#include <limits>

#include "mcap/ground_truth_message.h"
#include "mcap/mcap_writer.h"
#include "mcap/raw_image.h"
#include "mcap/recording_layout.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/json_input.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"
#include "tilth/version.h"

namespace tilth::mcap {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kRawPort = 0;
constexpr std::size_t kColorPort = 1;
constexpr std::size_t kTruthPort = 2;

std::uint64_t now_ns() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::system_clock::now().time_since_epoch())
                                        .count());
}

void check_image(std::string_view port, const cv::Mat& image, int type, cv::Size size) {
  if (image.type() != type || image.size() != size) {
    throw Error(std::string(port) + ": expected a " + std::to_string(size.width) + "x" +
                std::to_string(size.height) + " image of OpenCV type " + std::to_string(type) +
                " (the calibration's size), got " + std::to_string(image.cols) + "x" +
                std::to_string(image.rows) + " of type " + std::to_string(image.type()));
  }
}

std::uint64_t device_time(std::string_view port, std::int64_t timestamp_ns) {
  if (timestamp_ns < 0) {
    throw Error(std::string(port) + ": device timestamp " + std::to_string(timestamp_ns) +
                " ns; expected >= 0 (MCAP times are unsigned)");
  }
  return static_cast<std::uint64_t>(timestamp_ns);
}

// The frame's host capture time, or its depth device time when the host's is unknown (0).
std::uint64_t host_time(const FrameInfo& info, std::uint64_t depth_time) {
  if (info.host_timestamp_ns < 0) {
    throw Error("host timestamp " + std::to_string(info.host_timestamp_ns) +
                " ns; expected >= 0 (MCAP times are unsigned)");
  }
  return info.host_timestamp_ns != 0 ? static_cast<std::uint64_t>(info.host_timestamp_ns)
                                     : depth_time;
}

WriterOptions writer_options(const Params& params) {
  WriterOptions options;
  const std::string compression = params.string("compression");
  options.compression = compression == "none" ? "" : compression;
  options.chunk_size = static_cast<std::uint64_t>(params.integer("chunk_size"));
  options.store_when_behind = params.string("when_behind") == "store";
  return options;
}

class McapWriterStage final : public Sink {
 public:
  explicit McapWriterStage(const StageContext& context)
      : calibration_text_(read_json_text(context.params.path("calibration"), "calibration file")),
        calibration_(parse_calibration(
            parse_json(calibration_text_, context.params.path("calibration").string()),
            context.params.path("calibration").string())),
        depth_size_(calibration_.depth.width, calibration_.depth.height),
        color_size_(calibration_.color.width, calibration_.color.height),
        writer_(context.params.path("path"), writer_options(context.params)),
        log_host_time_(context.params.string("log_time") == "host"),
        log_(context.log),
        report_data_loss_(context.report_data_loss) {
    const std::uint64_t created = now_ns();
    writer_.add_attachment({created, created, std::string(kCalibrationAttachment),
                            "application/json", calibration_text_});
    writer_.add_metadata({std::string(kCalibrationMetadata), {{"json", calibration_text_}}});
    const fs::path graph = context.params.string("graph_file");
    std::map<std::string, std::string> recording{{"node", context.node},
                                                 {"log_time", context.params.string("log_time")},
                                                 {"tilth_version", std::string(version())}};
    if (!graph.empty()) {
      writer_.add_attachment({created, created, graph.filename().string(), "application/json",
                              read_json_text(graph, "graph file")});
      recording["graph_file"] = graph.filename().string();
    }
    writer_.add_metadata({std::string(kRecordingMetadata), recording});

    const std::string cdr(kCdrEncoding);
    const std::uint16_t image = writer_.add_schema(
        std::string(kRawImageSchemaName), std::string(kRos2MsgSchemaEncoding), raw_image_schema());
    const std::uint16_t truth =
        writer_.add_schema(std::string(kGroundTruthSchemaName), std::string(kJsonSchemaEncoding),
                           ground_truth_schema());
    raw_channel_ = writer_.add_channel(image, std::string(kRawTopic), cdr);
    color_channel_ = writer_.add_channel(image, std::string(kColorTopic), cdr);
    truth_channel_ =
        writer_.add_channel(truth, std::string(kTruthTopic), std::string(kJsonEncoding));
    mask_channel_ = writer_.add_channel(image, std::string(kMaskTopic), cdr);
  }

  void consume(const Frame& frame) override {
    const auto& raw = frame.input<RawTofFrame>(kRawPort);
    const auto& color = frame.input<ColorImage>(kColorPort);
    const Packet& truth_packet = frame.input(kTruthPort);
    const GroundTruth* truth = truth_packet.empty() ? nullptr : &truth_packet.get<GroundTruth>();
    // A truth that knows nothing (a replayed recording without any) is not recorded.
    if (truth != nullptr && !truth->distance_mm && truth->residue_mask.empty()) truth = nullptr;

    const std::uint64_t frame_id = frame.info().frame_id;
    if (frame_id > std::numeric_limits<std::uint32_t>::max()) {
      throw Error("frame id " + std::to_string(frame_id) +
                  " does not fit the 32-bit MCAP sequence number");
    }
    const auto sequence = static_cast<std::uint32_t>(frame_id);
    check_image("raw", raw.gray, CV_16UC1, depth_size_);
    check_image("color", color.pixels, CV_8UC(channels(color.format)), color_size_);
    const bool has_mask = truth != nullptr && !truth->residue_mask.empty();
    if (has_mask) check_image("truth mask", truth->residue_mask, CV_8UC1, depth_size_);
    const std::uint64_t raw_time = device_time("raw", raw.device_timestamp_ns);
    const std::uint64_t color_time = device_time("color", color.device_timestamp_ns);
    // Log times: the frame's host capture time for every message, or each image's device time.
    const std::uint64_t raw_log_time =
        log_host_time_ ? host_time(frame.info(), raw_time) : raw_time;
    const std::uint64_t color_log_time = log_host_time_ ? raw_log_time : color_time;

    ++frames_given_;
    if (!failure_.empty()) {
      report_data_loss_(
          1, "frame " + std::to_string(frame_id) +
                 " not recorded: the recording stopped at an earlier error: " + failure_);
      return;
    }
    try {
      write_frame(raw, color, truth, sequence, raw_log_time, color_log_time);
    } catch (const Error& error) {
      stop_recording(error.what());
    }
  }

  void finish() override {
    if (failure_.empty()) {
      try {
        writer_.finish();
      } catch (const Error& error) {
        stop_recording(error.what());
      }
    }
    if (!failure_.empty()) {
      log_.warning(std::to_string(frames_given_ - frames_stored_) + " of " +
                   std::to_string(frames_given_) + " frame(s) not recorded; " + failure_);
    }
  }

 private:
  void write_frame(const RawTofFrame& raw, const ColorImage& color, const GroundTruth* truth,
                   std::uint32_t sequence, std::uint64_t raw_log_time,
                   std::uint64_t color_log_time) {
    const bool has_mask = truth != nullptr && !truth->residue_mask.empty();
    writer_.write(raw_channel_, sequence, raw_log_time, raw_log_time,
                  encode_raw_image(raw.gray, "mono16", raw.device_timestamp_ns, kTofFrameId));
    writer_.write(color_channel_, sequence, color_log_time, color_log_time,
                  encode_raw_image(color.pixels, to_string(color.format), color.device_timestamp_ns,
                                   kColorFrameId));
    if (truth != nullptr) {
      writer_.write(truth_channel_, sequence, raw_log_time, raw_log_time,
                    encode_ground_truth(truth->distance_mm, has_mask, raw.device_timestamp_ns));
      if (has_mask) {
        writer_.write(
            mask_channel_, sequence, raw_log_time, raw_log_time,
            encode_raw_image(truth->residue_mask, "mono8", raw.device_timestamp_ns, kTofFrameId));
      }
    }
    messages_given_ += 2 + (truth != nullptr ? 1 : 0) + (has_mask ? 1 : 0);
    frame_ends_.push_back(messages_given_);
    writer_.close_chunk_if_full();
    count_stored_frames();
  }

  // Frames whose every message is in a chunk the file holds.
  void count_stored_frames() {
    while (!frame_ends_.empty() && frame_ends_.front() <= writer_.messages_written()) {
      frame_ends_.pop_front();
      ++frames_stored_;
    }
  }

  void stop_recording(const std::string& why) {
    failure_ = why;
    count_stored_frames();
    report_data_loss_(
        frames_given_ - frames_stored_,
        why + "; recording stopped: " + std::to_string(frames_given_ - frames_stored_) +
            " frame(s) not stored so far, the file keeps the " + std::to_string(frames_stored_) +
            " before (`tilth recording repair` gives it a summary)");
  }

  const std::string calibration_text_;
  const RigCalibration calibration_;
  const cv::Size depth_size_;
  const cv::Size color_size_;
  McapWriter writer_;
  const bool log_host_time_;
  const Logger log_;
  const std::function<void(std::uint64_t, const std::string&)> report_data_loss_;
  std::uint64_t frames_given_ = 0;
  std::uint64_t frames_stored_ = 0;
  std::uint64_t messages_given_ = 0;
  std::deque<std::uint64_t> frame_ends_;  // messages given by the end of each frame not stored
  std::string failure_;                   // why recording stopped; "" while it goes on
  std::uint16_t raw_channel_ = 0;
  std::uint16_t color_channel_ = 0;
  std::uint16_t truth_channel_ = 0;
  std::uint16_t mask_channel_ = 0;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "mcap.writer";
  d.summary = "records raw ToF, colour and ground truth as an MCAP file (Foxglove RawImage)";
  d.inputs = {
      PortSpec::of<RawTofFrame>("raw", "16-bit ToF gray, the calibration's depth_camera size"),
      PortSpec::of<ColorImage>("color", "bgr8, rgb8, mono8 or a Bayer mosaic"),
      PortSpec::of<GroundTruth>("truth", "ground truth distance and mask, when known").optional(),
  };
  d.params = {
      ParamSpec::path("path", std::nullopt)
          .describe("the MCAP file to create (replaced if it exists)"),
      ParamSpec::choice("compression", {"zstd", "lz4", "none"}, "zstd")
          .describe("chunk compression"),
      ParamSpec::choice("when_behind", {"store", "wait"}, "store")
          .describe("a chunk closed while two others are still being compressed: store it "
                    "uncompressed (the recording keeps up with the cameras) or wait for them"),
      ParamSpec::choice("log_time", {"host", "device"}, "host")
          .describe("the messages' log and publish time: the frame's host capture time (its "
                    "depth device time when unknown), or each image's device time (for frames "
                    "whose host time is not a capture time, such as an image folder without "
                    "host_timestamps.csv replays)"),
      ParamSpec::integer("chunk_size", 4 * 1024 * 1024)
          .range(1, 100'000'000)
          .in_unit("bytes")
          .describe("a chunk is closed after the frame that makes it this large"),
      ParamSpec::path("calibration", std::nullopt)
          .describe("the rig's calibration file; stored as the attachment rig.calib.json and as "
                    "metadata"),
      ParamSpec::string("graph_file", "")
          .describe("a graph file to store as an attachment (relative to the working directory); "
                    "\"\" = none"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<McapWriterStage>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::mcap
