// mcap.player: replays an MCAP recording that mcap.writer made, as fast as possible or
// paced by the depth images' device timestamps, optionally only a time window of it.
//
//   FILE.mcap ──> mcap.player ──> raw, color, truth, distance (what the machine measured,
//                                  when the recording holds it)
//
// Frames are rebuilt from the consecutive messages of a chunk that share a sequence
// number (the frame id), in the order the chunks were written. A frame's device times
// are its images' timestamps; its host capture time is when it is played, or with
// host_time: recorded the depth message's log time (for recordings whose log times are
// device times, the older ones, that is its device time).
// The window [start_s, end_s] is in log time, Foxglove's timeline. With a summary, the
// chunks outside it are skipped using the ChunkIndex records without being read; without
// one (a file cut off mid-write) the chunks found by scanning the file from the start
// are played and a warning says how much was recovered.
#include <algorithm>
#include <deque>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mcap/color_window_metadata.h"
#include "mcap/ground_truth_message.h"
#include "mcap/mcap_reader.h"
#include "mcap/measurement_messages.h"
#include "mcap/raw_image.h"
#include "mcap/recording_layout.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/json_input.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/playback_clock.h"
#include "tilth/plugin.h"
#include "tilth/replay_host_time.h"

namespace tilth::mcap {
namespace {

constexpr std::size_t kRawPort = 0;
constexpr std::size_t kColorPort = 1;
constexpr std::size_t kTruthPort = 2;
constexpr std::size_t kDistancePort = 3;

// The messages of one frame, still encoded.
struct RecordedFrame {
  std::uint32_t sequence = 0;
  std::optional<Message> raw;
  std::optional<Message> color;
  std::optional<Message> truth;
  std::optional<Message> mask;
  std::optional<Message> distance;
};

std::uint64_t seconds_to_ns(double seconds) {
  return static_cast<std::uint64_t>(seconds * 1e9 + 0.5);
}

std::string seconds_text(double seconds) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(3) << seconds << " s";
  return text.str();
}

RigCalibration read_calibration(McapReader& reader) {
  const std::optional<Attachment> attachment = reader.find_attachment(kCalibrationAttachment);
  if (!attachment) {
    throw Error(reader.file().string() + ": has no attachment named " +
                std::string(kCalibrationAttachment) + " (the rig calibration mcap.writer stores)");
  }
  const std::string origin = reader.file().string() + ":" + attachment->name;
  return parse_calibration(parse_json(attachment->data, origin), origin);
}

class McapPlayer final : public Source {
 public:
  explicit McapPlayer(const StageContext& context)
      : reader_(context.params.path("path")),
        calibration_(std::make_shared<const RigCalibration>(read_calibration(reader_))),
        color_window_(read_color_window(reader_, calibration_->color)),
        clock_(context.params.number("rate")),
        host_time_(context.params),
        log_(context.log) {
    for (const auto& [id, channel] : reader_.channels()) {
      if (channel.topic == kRawTopic) raw_channel_ = id;
      if (channel.topic == kColorTopic) color_channel_ = id;
      if (channel.topic == kTruthTopic) truth_channel_ = id;
      if (channel.topic == kMaskTopic) mask_channel_ = id;
      if (channel.topic == kDistanceTopic) distance_channel_ = id;
    }
    if (!raw_channel_ || !color_channel_) {
      throw Error(reader_.file().string() + ": expected channels " + std::string(kRawTopic) +
                  " and " + std::string(kColorTopic) + " (an mcap.writer recording)");
    }
    for (const auto& image_channel : {raw_channel_, color_channel_, mask_channel_}) {
      if (image_channel) check_image_channel(reader_.channels().at(*image_channel));
    }
    if (const auto& recovery = reader_.recovery()) {
      const std::string why = recovery->summary_problem.empty()
                                  ? "no summary (the recording was cut off while written?)"
                                  : "summary not used (" + recovery->summary_problem + ")";
      log_.warning(reader_.file().string() + ": " + why + "; recovered " +
                   std::to_string(reader_.chunks().size()) + " complete chunks, " +
                   std::to_string(recovery->readable_bytes) + " of " +
                   std::to_string(reader_.file_size()) + " bytes; " + recovery->stop_reason);
      for (const DamagedRange& range : recovery->skipped) {
        if (range.offset + range.size == reader_.file_size()) break;  // the rest: said above
        log_.warning(reader_.file().string() + ": skipped " + std::to_string(range.size) +
                     " damaged bytes at offset " + std::to_string(range.offset) + " (" +
                     range.reason + ")");
      }
    }
    select_chunks(context.params.number("start_s"), context.params.number("end_s"));
  }

  bool produce(Frame& frame) override {
    for (;;) {
      while (ready_.empty()) {
        if (next_chunk_ == chunks_.size()) return false;
        read_chunk(chunks_[next_chunk_++]);
      }
      RecordedFrame recorded = std::move(ready_.front());
      ready_.pop_front();
      if (!recorded.raw || !recorded.color) {
        log_.warning(reader_.file().string() + ": frame " + std::to_string(recorded.sequence) +
                     " lacks its " + std::string(recorded.raw ? kColorTopic : kRawTopic) +
                     " message; skipped");
        continue;
      }
      const std::uint64_t time = recorded.raw->log_time;
      if (time < start_ns_ || time > end_ns_) continue;
      Outputs outputs = decode(recorded);
      // Paced by the depth device times, relative to the first frame played.
      if (!clock_.wait(outputs.raw.device_timestamp_ns)) return false;
      emit(frame, recorded, std::move(outputs));
      return true;
    }
  }

  void interrupt() override { clock_.interrupt(); }

 private:
  // The window as absolute log times, from the recording's first message; the chunks
  // that overlap it.
  void select_chunks(double start_s, double end_s) {
    std::uint64_t first = std::numeric_limits<std::uint64_t>::max();
    std::uint64_t last = 0;
    if (reader_.statistics() && reader_.statistics()->message_count > 0) {
      first = reader_.statistics()->message_start_time;
      last = reader_.statistics()->message_end_time;
    } else {
      for (const ChunkIndex& chunk : reader_.chunks()) {
        first = std::min(first, chunk.message_start_time);
        last = std::max(last, chunk.message_end_time);
      }
    }
    const double duration_s = first <= last ? static_cast<double>(last - first) * 1e-9 : 0.0;
    if (start_s > duration_s) {
      throw Error(reader_.file().string() + ": start_s " + seconds_text(start_s) +
                  " is past the recording's end: it lasts " + seconds_text(duration_s) +
                  " (log time of its first to its last message); expected start_s <= that");
    }
    if (end_s > 0 && end_s < start_s) {
      throw Error("end_s " + std::to_string(end_s) + ": expected 0 (the end) or >= start_s " +
                  std::to_string(start_s));
    }
    start_ns_ = first + seconds_to_ns(start_s);
    end_ns_ = end_s > 0 && end_s <= duration_s ? first + seconds_to_ns(end_s)
                                               : std::numeric_limits<std::uint64_t>::max();
    for (const ChunkIndex& chunk : reader_.chunks()) {
      if (chunk.message_end_time < start_ns_ || chunk.message_start_time > end_ns_) continue;
      chunks_.push_back(chunk);
    }
    // In the order they were written, the frames' order: host log times may step back
    // (the host clock set by NTP) where device times and frame ids do not.
    std::sort(chunks_.begin(), chunks_.end(), [](const ChunkIndex& a, const ChunkIndex& b) {
      return a.chunk_start_offset < b.chunk_start_offset;
    });
  }

  // Groups the chunk's messages into frames by sequence number. mcap.writer never splits
  // a frame across chunks, so a frame ends with its chunk at the latest.
  void read_chunk(const ChunkIndex& chunk) {
    for (Message& message : reader_.read_chunk(chunk)) {
      if (ready_.empty() || ready_.back().sequence != message.sequence) {
        ready_.emplace_back();
        ready_.back().sequence = message.sequence;
      }
      RecordedFrame& frame = ready_.back();
      const std::uint16_t channel = message.channel_id;
      if (channel == raw_channel_) {
        frame.raw = std::move(message);
      } else if (channel == color_channel_) {
        frame.color = std::move(message);
      } else if (channel == truth_channel_) {
        frame.truth = std::move(message);
      } else if (channel == mask_channel_) {
        frame.mask = std::move(message);
      } else if (channel == distance_channel_) {
        frame.distance = std::move(message);
      }
    }
  }

  // Images are CDR-encoded RawImages; an older recording (JSON images) says so here,
  // before the graph runs.
  void check_image_channel(const Channel& channel) const {
    if (channel.message_encoding != kCdrEncoding) {
      throw Error(reader_.file().string() + ": channel " + channel.topic +
                  " has message encoding '" + channel.message_encoding + "'; expected '" +
                  std::string(kCdrEncoding) + "' (" + std::string(kRawImageSchemaName) +
                  " as mcap.writer records it)");
    }
  }

  std::string where(const Message& message) const {
    const auto& topic = reader_.channels().at(message.channel_id).topic;
    return reader_.file().string() + ": " + topic + " frame " + std::to_string(message.sequence);
  }

  // The image of a message, in `size` (`size_from` says whose); `encoding` "" accepts any.
  RawImage image(const Message& message, cv::Size size, std::string_view encoding,
                 std::string_view size_from = "the calibration's size") const {
    RawImage decoded = decode_raw_image(message.data, where(message));
    if (!encoding.empty() && decoded.encoding != encoding) {
      throw Error(where(message) + ": expected encoding " + std::string(encoding) + ", got " +
                  decoded.encoding);
    }
    if (decoded.pixels.size() != size) {
      throw Error(where(message) + ": expected " + std::to_string(size.width) + "x" +
                  std::to_string(size.height) + " (" + std::string(size_from) + "), got " +
                  std::to_string(decoded.pixels.cols) + "x" + std::to_string(decoded.pixels.rows));
    }
    return decoded;
  }

  struct Outputs {
    RawTofFrame raw;
    ColorImage color;
    GroundTruth truth;
    std::optional<GroundDistance> distance;
  };

  Outputs decode(const RecordedFrame& recorded) const {
    const cv::Size depth_size(calibration_->depth.width, calibration_->depth.height);
    const cv::Size color_size =
        color_window_ ? color_window_->size()
                      : cv::Size(calibration_->color.width, calibration_->color.height);
    Outputs outputs;

    RawImage raw_image = image(*recorded.raw, depth_size, "mono16");
    outputs.raw.gray = std::move(raw_image.pixels);
    outputs.raw.device_timestamp_ns = raw_image.timestamp_ns;
    outputs.raw.rig = calibration_;

    RawImage color_image =
        image(*recorded.color, color_size, "",
              color_window_ ? "the recording's colour window" : "the calibration's size");
    const std::optional<PixelFormat> format = parse_pixel_format(color_image.encoding);
    if (!format) {
      throw Error(where(*recorded.color) + ": encoding " + color_image.encoding +
                  " is not a Tilth pixel format");
    }
    outputs.color.format = *format;
    outputs.color.pixels = std::move(color_image.pixels);
    outputs.color.device_timestamp_ns = color_image.timestamp_ns;
    if (color_window_) outputs.color.sensor_offset = color_window_->tl();

    if (recorded.truth) {
      outputs.truth.distance_mm =
          decode_ground_truth(recorded.truth->data, where(*recorded.truth)).distance_mm;
    }
    if (recorded.mask) {
      outputs.truth.residue_mask = image(*recorded.mask, depth_size, "mono8").pixels;
    }
    if (recorded.distance) {
      outputs.distance = decode_ground_distance(recorded.distance->data, where(*recorded.distance));
    }
    return outputs;
  }

  void emit(Frame& frame, const RecordedFrame& recorded, Outputs outputs) const {
    frame.set_capture(recorded.sequence, outputs.raw.device_timestamp_ns,
                      host_time_.stamp(static_cast<std::int64_t>(recorded.raw->log_time)));
    frame.emit(kRawPort, std::move(outputs.raw));
    frame.emit(kColorPort, std::move(outputs.color));
    frame.emit(kTruthPort, std::move(outputs.truth));
    if (outputs.distance) frame.emit(kDistancePort, std::move(*outputs.distance));
  }

  McapReader reader_;
  const std::shared_ptr<const RigCalibration> calibration_;  // the frames carry it
  const std::optional<cv::Rect> color_window_;  // the colour images' window of the sensor
  PlaybackClock clock_;
  const ReplayHostTime host_time_;
  const Logger log_;
  std::optional<std::uint16_t> raw_channel_;
  std::optional<std::uint16_t> color_channel_;
  std::optional<std::uint16_t> truth_channel_;
  std::optional<std::uint16_t> mask_channel_;
  std::optional<std::uint16_t> distance_channel_;

  std::uint64_t start_ns_ = 0;
  std::uint64_t end_ns_ = 0;
  std::vector<ChunkIndex> chunks_;  // the ones to play, in time order
  std::size_t next_chunk_ = 0;
  std::deque<RecordedFrame> ready_;  // decoded from the chunks read so far, not yet played
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "mcap.player";
  d.summary = "replays an MCAP recording made by mcap.writer, also one cut off mid-write";
  d.outputs = {
      PortSpec::of<RawTofFrame>("raw", "16-bit ToF gray; device time = the image's timestamp"),
      PortSpec::of<ColorImage>("color",
                               "the colour image as recorded; device time = the image's timestamp"),
      PortSpec::of<GroundTruth>("truth", "the recorded distance and mask; empty when none"),
      PortSpec::of<GroundDistance>("distance",
                                   "what the machine measured (/tilth/distance), for the frames "
                                   "that have it; nothing for the others"),
  };
  d.params = {
      ParamSpec::path("path", std::nullopt).describe("the MCAP file"),
      ParamSpec::number("rate", 0.0)
          .range(0, std::nullopt)
          .describe("playback speed: 0 = as fast as possible, 1 = as recorded (paced by the depth "
                    "images' device timestamps), 2 = twice as fast"),
      ParamSpec::number("start_s", 0.0)
          .range(0, std::nullopt)
          .in_unit("s")
          .describe(
              "first frame to play, by its log time (the recorded host capture time), from the "
              "recording's first message"),
      ParamSpec::number("end_s", 0.0)
          .range(0, std::nullopt)
          .in_unit("s")
          .describe(
              "last frame to play, by its log time (the recorded host capture time), from the "
              "recording's first message; 0 = the end"),
      ReplayHostTime::param("the depth message's log time"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<McapPlayer>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::mcap
