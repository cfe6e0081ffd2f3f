// Replays an image-folder recording (spec: tilth-image-folder/1): raw ToF frames, colour
// images and ground truth, in frames.csv order, as fast as possible or paced by the
// depth timestamps, stamped when they are played or, with host_time: recorded, with the
// host capture times of host_timestamps.csv when the folder has one. recording.json, all
// of frames.csv and host_timestamps.csv are checked before the first frame, whichever
// host times are used, so a malformed recording fails before the graph runs; the PNGs
// are read frame by frame, `decode_ahead` frames ahead of the graph, each on a thread of
// its own (decoding PNGs, not the measurement, bounds a replay), and played in order.
// Every file is read only when it is a regular file (a FIFO or a device named in a
// recording would block the replay) within a size limit.
#include <algorithm>
#include <deque>
#include <future>
#include <optional>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "image_folder/frames_csv.h"
#include "image_folder/host_timestamps_csv.h"
#include "image_folder/image_file.h"
#include "image_folder/pixel_checks.h"
#include "image_folder/recording_json.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/playback_clock.h"
#include "tilth/plugin.h"
#include "tilth/replay_host_time.h"

namespace tilth::recording {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kRawPort = 0;
constexpr std::size_t kColorPort = 1;
constexpr std::size_t kTruthPort = 2;
constexpr std::string_view kDepthSize = "depth_camera in the calibration";

// Each frame's host capture time from host_timestamps.csv; none without the file.
std::vector<std::int64_t> recorded_host_timestamps(const fs::path& folder,
                                                   const std::vector<FrameEntry>& frames) {
  const fs::path file = folder / kHostTimestampsFile;
  if (!fs::exists(file)) return {};
  return read_host_timestamps(file, frames);
}

struct FrameImages {
  cv::Mat depth;
  cv::Mat color;
  cv::Mat mask;  // empty: the frame has no mask
};

// A frame's images as decoded ahead, or why the frame is skipped (on_missing: skip),
// logged when the frame's turn comes so that the log keeps the frames' order.
struct DecodedFrame {
  std::optional<FrameImages> images;
  std::string skipped;
};

class ImageFolderSource final : public Source {
 public:
  explicit ImageFolderSource(const StageContext& context)
      : folder_(context.params.path("path")),
        recording_(read_recording_json(folder_)),
        rig_(std::make_shared<const RigCalibration>(recording_.calibration)),
        frames_(read_frames_csv(folder_ / "frames.csv")),
        host_timestamps_(recorded_host_timestamps(folder_, frames_)),
        host_time_(context.params),
        clock_(context.params.number("rate")),
        stop_on_missing_(context.params.string("on_missing") == "stop"),
        loop_(context.params.boolean("loop")),
        decode_ahead_(frames_decoded_ahead(context.params.integer("decode_ahead"))),
        log_(context.log) {
    // OpenCV lists its codecs on first use, behind a guard that ThreadSanitizer cannot see
    // in uninstrumented OpenCV; listing them here, before a decoding thread starts, orders
    // that listing before every decoding for it too.
    cv::haveImageWriter(".png");
  }

  bool produce(Frame& frame) override {
    for (;;) {
      if (next_ == frames_.size()) {
        if (!loop_ || frames_.empty()) return false;
        if (!produced_this_pass_) {
          log_.warning(folder_.string() + ": no frame of the recording could be read; not looping");
          return false;
        }
        next_ = 0;
        queued_ = 0;
      }
      if (next_ == 0) {
        clock_.restart();
        produced_this_pass_ = false;
      }
      const std::size_t position = next_++;
      const FrameEntry& entry = frames_[position];
      // Paced by the depth timestamps, relative to the first frame of the pass.
      queue_ahead(position);
      if (!clock_.wait(entry.depth_timestamp_ns)) return false;
      if (auto images = take_images(position)) {
        emit(frame, entry, host_timestamp(position), std::move(*images));
        produced_this_pass_ = true;
        return true;
      }
    }
  }

  void interrupt() override { clock_.interrupt(); }

 private:
  using Decoding = std::future<DecodedFrame>;

  static std::size_t frames_decoded_ahead(std::int64_t asked) {
    if (asked > 0) return static_cast<std::size_t>(asked);
    return std::max(1u, std::thread::hardware_concurrency());
  }

  // Starts decoding the frames after those in ahead_, up to decode_ahead_ frames from
  // `position` on, within this pass.
  void queue_ahead(std::size_t position) {
    while (queued_ < frames_.size() && queued_ < position + decode_ahead_) {
      const FrameEntry& entry = frames_[queued_++];
      ahead_.push_back(
          std::async(std::launch::async, [this, &entry] { return read_images(entry); }));
    }
  }

  // The images of the frame at `position`, the oldest decoding; a failure to read them
  // (on_missing: stop, a wrong size) is thrown here, in the frames' order.
  std::optional<FrameImages> take_images(std::size_t position) {
    Decoding decoding = std::move(ahead_.front());
    ahead_.pop_front();
    queue_ahead(position + 1);
    DecodedFrame decoded = decoding.get();
    if (!decoded.skipped.empty()) log_.warning(decoded.skipped);
    return std::move(decoded.images);
  }

  // The frame's images, checked, or why it is skipped when one is missing or unreadable
  // and on_missing is skip. Runs on the decoding threads: reads only what does not change.
  DecodedFrame read_images(const FrameEntry& entry) const {
    const cv::Size depth_size(recording_.calibration.depth.width,
                              recording_.calibration.depth.height);
    const cv::Size color_size =
        recording_.color_window
            ? recording_.color_window->size()
            : cv::Size(recording_.calibration.color.width, recording_.calibration.color.height);
    DecodedFrame decoded;
    FrameImages images;
    images.depth =
        read_image(entry, entry.depth, CV_16UC1, depth_size, kDepthSize, decoded.skipped);
    if (images.depth.empty()) return decoded;
    images.color =
        read_image(entry, entry.color, CV_8UC(channels(recording_.color_format)), color_size,
                   recording_.color_window ? "color_window in recording.json"
                                           : "color_camera in the calibration",
                   decoded.skipped);
    if (images.color.empty()) return decoded;
    if (!entry.mask.empty()) {
      images.mask = read_image(entry, entry.mask, CV_8UC1, depth_size, kDepthSize, decoded.skipped);
      if (images.mask.empty()) return decoded;
    }
    decoded.images = std::move(images);
    return decoded;
  }

  // An empty image, and `skipped` saying why, when the file is missing or unreadable and
  // on_missing is skip.
  // `size_from` says where `size` comes from, for the error.
  cv::Mat read_image(const FrameEntry& entry, const std::string& relative, int type, cv::Size size,
                     std::string_view size_from, std::string& skipped) const {
    const fs::path file = folder_ / relative;
    const std::string where =
        file.string() + " (frames.csv line " + std::to_string(entry.line) + ")";
    cv::Mat image;
    std::string problem;
    try {
      image = read_image_file(file);
    } catch (const Error& error) {
      const std::string prefix = file.string() + ": ";
      const std::string text = error.what();
      problem = text.starts_with(prefix) ? text.substr(prefix.size()) : text;
    }
    if (!problem.empty()) {
      if (stop_on_missing_) throw Error(where + ": " + problem + " (on_missing: stop)");
      skipped = where + ": " + problem + "; frame " + std::to_string(entry.index) +
                " skipped (on_missing: skip)";
      return {};
    }
    const std::string mismatch = pixel_mismatch(image, type, size, std::string(size_from));
    if (!mismatch.empty()) throw Error(where + ": " + mismatch);
    return image;
  }

  std::int64_t host_timestamp(std::size_t position) const {
    if (host_timestamps_.empty()) return host_time_.stamp(std::nullopt);
    return host_time_.stamp(host_timestamps_[position]);
  }

  void emit(Frame& frame, const FrameEntry& entry, std::int64_t host_timestamp_ns,
            FrameImages images) const {
    frame.set_capture(entry.index, entry.depth_timestamp_ns, host_timestamp_ns);
    RawTofFrame raw;
    raw.gray = std::move(images.depth);
    raw.device_timestamp_ns = entry.depth_timestamp_ns;
    raw.rig = rig_;
    frame.emit(kRawPort, std::move(raw));
    ColorImage color;
    color.pixels = std::move(images.color);
    color.format = recording_.color_format;
    color.device_timestamp_ns = entry.color_timestamp_ns;
    if (recording_.color_window) color.sensor_offset = recording_.color_window->tl();
    frame.emit(kColorPort, std::move(color));
    GroundTruth truth;
    truth.distance_mm = entry.ground_truth_mm;
    truth.residue_mask = std::move(images.mask);
    frame.emit(kTruthPort, std::move(truth));
  }

  const fs::path folder_;
  const RecordingJson recording_;
  const std::shared_ptr<const RigCalibration> rig_;  // the frames carry it
  const std::vector<FrameEntry> frames_;
  const std::vector<std::int64_t> host_timestamps_;  // one per frame; empty: not recorded
  const ReplayHostTime host_time_;
  PlaybackClock clock_;
  const bool stop_on_missing_;
  const bool loop_;
  const std::size_t decode_ahead_;
  const Logger log_;

  std::size_t next_ = 0;  // the next entry of frames_
  bool produced_this_pass_ = false;
  std::size_t queued_ = 0;      // the entry after the last one decoding
  std::deque<Decoding> ahead_;  // entries [next_ or the one being played, queued_); last:
                                // destroyed first, each waiting for its decoding to end
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "recording.image_folder";
  d.summary = "replays an image-folder recording (PNG files and frames.csv)";
  d.outputs = {
      PortSpec::of<RawTofFrame>("raw", "16-bit ToF gray; device time = depth_timestamp_ns"),
      PortSpec::of<ColorImage>("color",
                               "bgr8 or a Bayer mosaic as recorded; device time = "
                               "color_timestamp_ns"),
      PortSpec::of<GroundTruth>("truth",
                                "ground_truth_mm and the mask when the recording has them"),
  };
  d.params = {
      ParamSpec::path("path", std::nullopt).describe("the recording folder"),
      ParamSpec::number("rate", 0.0)
          .range(0, std::nullopt)
          .describe("playback speed: 0 = as fast as possible, 1 = as recorded (paced by the depth "
                    "timestamps), 2 = twice as fast"),
      ParamSpec::choice("on_missing", {"skip", "stop"}, "skip")
          .describe("a missing or unreadable PNG: skip the frame with a warning, or stop"),
      ParamSpec::boolean("loop", false).describe("start again after the last frame"),
      ParamSpec::integer("decode_ahead", 0)
          .range(0, 64)
          .describe("frames read and decoded ahead of the graph, each on a thread of its "
                    "own; 0 = as many as the machine has cores"),
      ReplayHostTime::param("host_timestamps.csv's, or when played without it"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<ImageFolderSource>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::recording
