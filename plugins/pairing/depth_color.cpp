// pairing.depth_color: lines up a depth camera and a colour camera into frames of the
// graph, each carrying one depth frame and the colour frame captured with it. Free-running
// cameras are paired by capture time (each camera's clock put on the host's by
// CaptureClock), triggered ones by trigger order. While a camera is lost (its source
// sends no image, and says why on its status port) every status it sends becomes a frame
// without images, so the measurement turns invalid within a frame period.
#include <array>
#include <memory>

#include "capture_clock.h"
#include "order_matcher.h"
#include "tilth/messages/camera_status.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"
#include "time_matcher.h"

namespace tilth::pairing {
namespace {

constexpr std::int64_t kNsPerMs = 1'000'000;

enum InputPort { kDepthIn, kDepthStatusIn, kColorIn, kColorStatusIn };
enum OutputPort { kDepthOut, kColorOut, kCamerasOut };

constexpr std::array<const char*, 2> kSideNames{"depth", "colour"};

std::unique_ptr<FrameMatcher> make_matcher(const Params& params) {
  const auto tolerance = static_cast<std::int64_t>(params.number("tolerance_ms") * kNsPerMs);
  const auto max_wait = static_cast<std::int64_t>(params.number("max_wait_ms") * kNsPerMs);
  if (params.string("mode") == "triggered") {
    return std::make_unique<OrderMatcher>(tolerance, max_wait);
  }
  return std::make_unique<TimeMatcher>(tolerance, max_wait);
}

class DepthColorPairing final : public Synchronizer {
 public:
  explicit DepthColorPairing(const StageContext& context)
      : log_(context.log),
        matcher_(make_matcher(context.params)),
        clocks_{CaptureClock(static_cast<std::int64_t>(context.params.number("clock_window_s") *
                                                       1000 * kNsPerMs)),
                CaptureClock(static_cast<std::int64_t>(context.params.number("clock_window_s") *
                                                       1000 * kNsPerMs))},
        color_delay_ns_(
            static_cast<std::int64_t>(context.params.number("color_delay_ms") * kNsPerMs)) {}

  void accept(const Frame& arrived, Output& output) override {
    const bool from_depth =
        !arrived.input(kDepthIn).empty() || !arrived.input(kDepthStatusIn).empty();
    const Side side = from_depth ? kDepth : kColor;
    const Packet& image = arrived.input(from_depth ? kDepthIn : kColorIn);
    const Packet& status = arrived.input(from_depth ? kDepthStatusIn : kColorStatusIn);
    if (!status.empty()) status_[side] = status.share<CameraStatus>();
    note_streaming(side, !image.empty());

    const FrameInfo& info = arrived.info();
    if (image.empty()) {
      matcher_->clear();
      Frame& frame = output.emit();
      frame.set_capture(info.frame_id, info.device_timestamp_ns, info.host_timestamp_ns);
      frame.set_output(kCamerasOut, combined_status());
      return;
    }
    std::int64_t capture =
        clocks_[side].capture_ns(info.device_timestamp_ns, info.host_timestamp_ns);
    if (side == kColor) capture -= color_delay_ns_;
    for (auto& pair : matcher_->add(side, {capture, info, image})) {
      ++paired_;
      const FrameInfo& depth = pair.depth.info;
      Frame& frame = output.emit();
      frame.set_capture(depth.frame_id, depth.device_timestamp_ns, depth.host_timestamp_ns);
      frame.set_output(kDepthOut, pair.depth.image.message());
      frame.set_output(kColorOut, pair.color.image.message());
      frame.set_output(kCamerasOut, combined_status());
    }
  }

  void finish() override {
    log_.info(std::to_string(paired_) +
              " pairs; unmatched and dropped: " + std::to_string(matcher_->unmatched(kDepth)) +
              " depth, " + std::to_string(matcher_->unmatched(kColor)) + " colour frames");
  }

 private:
  void note_streaming(Side side, bool streaming) {
    if (streaming == streaming_[side]) return;
    streaming_[side] = streaming;
    const std::string problem = status_[side] ? status_[side]->problem : "";
    if (streaming) {
      log_.info(std::string(kSideNames[side]) + " camera streams; pairing resumes");
    } else {
      log_.warning(std::string(kSideNames[side]) + " camera sends no images" +
                   (problem.empty() ? "" : " (" + problem + ")") +
                   "; frames go out without images until it is back");
    }
  }

  std::shared_ptr<const CameraStatus> combined_status() const {
    auto combined = std::make_shared<CameraStatus>();
    combined->camera = "depth+color";
    combined->streaming = streaming_[kDepth] && streaming_[kColor];
    combined->completed = paired_;
    for (Side side : {kDepth, kColor}) {
      if (!streaming_[side]) {
        const std::string problem = status_[side] ? status_[side]->problem : "no images";
        if (!combined->problem.empty()) combined->problem += "; ";
        combined->problem += std::string(kSideNames[side]) + ": " + problem;
      }
      if (!status_[side]) continue;
      combined->incomplete += status_[side]->incomplete;
      combined->lost += status_[side]->lost;
      combined->late += status_[side]->late;
    }
    return combined;
  }

  Logger log_;
  std::unique_ptr<FrameMatcher> matcher_;
  std::array<CaptureClock, 2> clocks_;
  const std::int64_t color_delay_ns_;
  std::array<std::shared_ptr<const CameraStatus>, 2> status_;
  std::array<bool, 2> streaming_{true, true};
  std::uint64_t paired_ = 0;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "pairing.depth_color";
  d.summary = "pairs a depth camera's frames with a colour camera's by capture time or trigger";
  d.inputs = {
      PortSpec::of<RawTofFrame>("depth", "the depth camera's frames; none while it is lost"),
      PortSpec::of<CameraStatus>("depth_status", "the depth camera's health").optional(),
      PortSpec::of<ColorImage>("color", "the colour camera's frames; none while it is lost"),
      PortSpec::of<CameraStatus>("color_status", "the colour camera's health").optional(),
  };
  d.outputs = {
      PortSpec::of<RawTofFrame>("depth", "the pair's depth frame"),
      PortSpec::of<ColorImage>("color", "the colour frame captured with it"),
      PortSpec::of<CameraStatus>("cameras", "both cameras' health, with every frame"),
  };
  d.params = {
      ParamSpec::choice("mode", {"free_running", "triggered"}, "free_running")
          .describe("free_running: pair by capture time; triggered: by trigger order"),
      ParamSpec::number("tolerance_ms", 8.0)
          .range(0.01, 1000.0)
          .in_unit("ms")
          .describe("largest capture-time difference of a pair; keep below half a frame period"),
      ParamSpec::number("max_wait_ms", 150.0)
          .range(1.0, 10000.0)
          .in_unit("ms")
          .describe("a frame whose partner has not come within this is dropped"),
      ParamSpec::number("clock_window_s", 2.0)
          .range(0.1, 600.0)
          .in_unit("s")
          .describe("window over which each camera's clock offset to the host is tracked"),
      ParamSpec::number("color_delay_ms", 0.0)
          .range(-1000.0, 1000.0)
          .in_unit("ms")
          .describe("how much later colour frames reach the host than depth frames of the "
                    "same instant, at the least (transfer time difference)"),
  };
  d.concurrency = Concurrency::kSerial;
  d.input_timing = InputTiming::kOnArrival;
  d.create = factory<DepthColorPairing>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::pairing
