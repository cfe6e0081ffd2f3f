// mcap.writer: records raw ToF frames, colour images and ground truth as an MCAP file
// that mcap.player replays and Foxglove opens as it is, and beside them, when the graph
// gives them, what the chain measured: the distance, the residue mask, the registered
// colour and the cameras' health.
//
//   raw ──────────┐
//   color ────────┤
//   truth ────────┤             FILE.mcap: /tof/raw, /color/image, /truth, /truth/mask,
//   distance ─────┼─> mcap.writer ──> /tilth/distance, /tilth/mask, /tilth/registered_color,
//   mask ─────────┤             /tilth/cameras; the rig once: /tof/calibration,
//   registered ───┤             /color/calibration, /tf
//   cameras ──────┘  (all but raw and color optional)
//
// Invariant: a frame's messages are never split across chunks (a chunk is closed only
// between frames), so a file cut off mid-write loses whole frames, never half of one.
//
// A write that fails (a full disk) stops the recording, not the graph: the file keeps
// the chunks written before it, without a summary (`tilth recording repair` adds one),
// and every frame not stored is reported as lost data.
//
// Colour images that are a window of the sensor (a camera's region of interest) are
// recorded with that window (metadata tilth.color_window, RecordedColorWindow), and
// /color/calibration holds the window's intrinsics.
//
// As in a ROS 2 bag, a message's log (and publish) time is when the frame was captured
// on the host's clock, so Foxglove shows wall-clock dates; each image's own timestamp
// is its device time.
#include <chrono>
#include <deque>
#include <functional>
#include <limits>
#include <optional>

#include "color_window/recorded_color_window.h"
#include "mcap/color_window_metadata.h"
#include "mcap/ground_truth_message.h"
#include "mcap/mcap_writer.h"
#include "mcap/measurement_messages.h"
#include "mcap/raw_image.h"
#include "mcap/recording_layout.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/json_input.h"
#include "tilth/messages/camera_status.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/plugin.h"
#include "tilth/version.h"

namespace tilth::mcap {
namespace {

namespace fs = std::filesystem;

const std::string kCdr(kCdrEncoding);

constexpr std::size_t kRawPort = 0;
constexpr std::size_t kColorPort = 1;
constexpr std::size_t kTruthPort = 2;
constexpr std::size_t kDistancePort = 3;
constexpr std::size_t kMaskPort = 4;
constexpr std::size_t kRegisteredPort = 5;
constexpr std::size_t kCamerasPort = 6;

// A frame's optional inputs, null where the graph gave none.
struct Measured {
  const GroundDistance* distance = nullptr;
  const ResidueMask* mask = nullptr;
  const RegisteredColor* registered = nullptr;
  const CameraStatus* cameras = nullptr;
};

template <class T>
const T* optional_input(const Frame& frame, std::size_t port) {
  const Packet& packet = frame.input(port);
  return packet.empty() ? nullptr : &packet.get<T>();
}

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
        color_window_(calibration_.color),
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
    const std::uint16_t calibration =
        json_schema(kCameraCalibrationSchemaName, camera_calibration_schema());
    tof_calibration_channel_ = json_channel(calibration, kTofCalibrationTopic);
    color_calibration_channel_ = json_channel(calibration, kColorCalibrationTopic);
    transform_channel_ = json_channel(
        json_schema(kFrameTransformSchemaName, frame_transform_schema()), kTransformTopic);
    image_schema_ = image;
  }

  void consume(const Frame& frame) override {
    const auto& raw = frame.input<RawTofFrame>(kRawPort);
    const auto& color = frame.input<ColorImage>(kColorPort);
    const Measured measured{optional_input<GroundDistance>(frame, kDistancePort),
                            optional_input<ResidueMask>(frame, kMaskPort),
                            optional_input<RegisteredColor>(frame, kRegisteredPort),
                            optional_input<CameraStatus>(frame, kCamerasPort)};
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
    const cv::Rect window = color_window_.check(color);
    check_image("color", color.pixels, CV_8UC(channels(color.format)), window.size());
    const bool has_mask = truth != nullptr && !truth->residue_mask.empty();
    if (has_mask) check_image("truth mask", truth->residue_mask, CV_8UC1, depth_size_);
    if (measured.mask != nullptr) check_image("mask", measured.mask->values, CV_8UC1, depth_size_);
    if (measured.registered != nullptr) {
      check_image("registered", measured.registered->bgr, CV_8UC3, depth_size_);
    }
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
      write_frame(raw, color, window, truth, measured, sequence, raw_log_time, color_log_time);
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
  void write_frame(const RawTofFrame& raw, const ColorImage& color, const cv::Rect& window,
                   const GroundTruth* truth, const Measured& measured, std::uint32_t sequence,
                   std::uint64_t raw_log_time, std::uint64_t color_log_time) {
    const bool has_mask = truth != nullptr && !truth->residue_mask.empty();
    const std::int64_t time = raw.device_timestamp_ns;
    // Channels of what the chain measured are added with the first frame that has it,
    // before any of that frame's messages: chunks still close only between frames.
    if (measured.distance != nullptr && !distance_channel_) {
      distance_channel_ = json_channel(
          json_schema(kGroundDistanceSchemaName, ground_distance_schema()), kDistanceTopic);
    }
    if (measured.cameras != nullptr && !cameras_channel_) {
      cameras_channel_ = json_channel(json_schema(kCameraStatusSchemaName, camera_status_schema()),
                                      kCameraStatusTopic);
    }
    if (measured.mask != nullptr && !residue_mask_channel_) {
      residue_mask_channel_ =
          writer_.add_channel(image_schema_, std::string(kResidueMaskTopic), kCdr);
    }
    if (measured.registered != nullptr && !registered_channel_) {
      registered_channel_ =
          writer_.add_channel(image_schema_, std::string(kRegisteredColorTopic), kCdr);
    }
    std::uint64_t messages = 0;
    const auto put = [&](std::uint16_t channel, std::uint64_t log_time, std::string_view data) {
      writer_.write(channel, sequence, log_time, log_time, data);
      ++messages;
    };
    if (!rig_written_) {
      color_window_.take(window);
      // The images' own intrinsics, as viewers expect of /color/calibration.
      RigCalibration rig = calibration_;
      if (const auto stored = color_window_.stored()) {
        writer_.add_metadata(color_window_metadata(*stored));
        rig = with_color_window(calibration_, *stored);
      }
      put(tof_calibration_channel_, raw_log_time,
          encode_camera_calibration(rig.depth, kTofFrameId, time));
      put(color_calibration_channel_, raw_log_time,
          encode_camera_calibration(rig.color, kColorFrameId, time));
      put(transform_channel_, raw_log_time,
          encode_color_pose(rig, kTofFrameId, kColorFrameId, time));
      rig_written_ = true;
    }
    put(raw_channel_, raw_log_time, encode_raw_image(raw.gray, "mono16", time, kTofFrameId));
    put(color_channel_, color_log_time,
        encode_raw_image(color.pixels, to_string(color.format), color.device_timestamp_ns,
                         kColorFrameId));
    if (truth != nullptr) {
      put(truth_channel_, raw_log_time, encode_ground_truth(truth->distance_mm, has_mask, time));
      if (has_mask) {
        put(mask_channel_, raw_log_time,
            encode_raw_image(truth->residue_mask, "mono8", time, kTofFrameId));
      }
    }
    if (measured.distance != nullptr) {
      put(*distance_channel_, raw_log_time, encode_ground_distance(*measured.distance, time));
    }
    if (measured.mask != nullptr) {
      put(*residue_mask_channel_, raw_log_time,
          encode_raw_image(measured.mask->values, "mono8", time, kTofFrameId));
    }
    if (measured.registered != nullptr) {
      put(*registered_channel_, raw_log_time,
          encode_raw_image(measured.registered->bgr, "bgr8", time, kTofFrameId));
    }
    if (measured.cameras != nullptr) {
      put(*cameras_channel_, raw_log_time, encode_camera_status(*measured.cameras, time));
    }
    messages_given_ += messages;
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

  std::uint16_t json_schema(std::string_view name, const std::string& schema) {
    return writer_.add_schema(std::string(name), std::string(kJsonSchemaEncoding), schema);
  }

  std::uint16_t json_channel(std::uint16_t schema, std::string_view topic) {
    return writer_.add_channel(schema, std::string(topic), std::string(kJsonEncoding));
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
  RecordedColorWindow color_window_;
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
  std::uint16_t image_schema_ = 0;
  std::uint16_t tof_calibration_channel_ = 0;
  std::uint16_t color_calibration_channel_ = 0;
  std::uint16_t transform_channel_ = 0;
  bool rig_written_ = false;  // the calibrations and the pose, with the first frame
  std::optional<std::uint16_t> distance_channel_;
  std::optional<std::uint16_t> residue_mask_channel_;
  std::optional<std::uint16_t> registered_channel_;
  std::optional<std::uint16_t> cameras_channel_;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "mcap.writer";
  d.summary =
      "records raw ToF, colour, ground truth and what the chain measured as an MCAP file "
      "(Foxglove RawImage, CameraCalibration, FrameTransform; the distance as JSON)";
  d.inputs = {
      PortSpec::of<RawTofFrame>("raw", "16-bit ToF gray, the calibration's depth_camera size"),
      PortSpec::of<ColorImage>("color", "bgr8, rgb8, mono8 or a Bayer mosaic"),
      PortSpec::of<GroundTruth>("truth", "ground truth distance and mask, when known").optional(),
      PortSpec::of<GroundDistance>("distance", "the distance the chain measured").optional(),
      PortSpec::of<ResidueMask>("mask", "the chain's residue mask, in the depth grid").optional(),
      PortSpec::of<RegisteredColor>("registered", "the colour on the depth grid").optional(),
      PortSpec::of<CameraStatus>("cameras", "the cameras' health").optional(),
  };
  d.params = {
      ParamSpec::output_path("path", std::nullopt)
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
