#include "camera_pairs.h"

#include "color/color_conversion.h"
#include "in_process_graph.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/stage_descriptor.h"

namespace tilth::calibrate {
namespace {

constexpr const char* kProgram = "tilth calibrate capture";
constexpr const char* kLookerType = "calibrate.pairs";

cv::Mat bgr_or_gray(const ColorImage& color) {
  if (color.format == PixelFormat::kMono8) return color.pixels.clone();
  cv::Mat bgr;
  color::to_bgr(color.pixels, color.format, bgr);
  return bgr;
}

class PairLooker final : public Sink {
 public:
  enum Port { kIntensity = 0, kColor = 1 };

  PairLooker(const std::function<bool(const FramePair&)>& on_pair, tools::InProcessGraph& graph)
      : on_pair_(on_pair), graph_(graph) {}

  void consume(const Frame& frame) override {
    if (done_) return;
    const auto& intensity = frame.input<RawTofFrame>(kIntensity).gray;
    const ColorImage& color = frame.input<ColorImage>(kColor);
    // A calibration is of the whole image; a window lying at the sensor's corner cannot be
    // told from it here.
    if (color.sensor_offset && *color.sensor_offset != cv::Point()) {
      throw Error("the colour images are a window of the sensor (" +
                  window_text(color.sensor_window()) +
                  "); calibrate with the whole image: OffsetX and OffsetY 0, Width and Height "
                  "the sensor's");
    }
    if (!on_pair_({frame.info().frame_id, intensity.clone(), bgr_or_gray(color)})) {
      done_ = true;
      graph_.stop();
    }
  }

 private:
  const std::function<bool(const FramePair&)>& on_pair_;
  tools::InProcessGraph& graph_;
  bool done_ = false;
};

StageDescriptor looker(const std::function<bool(const FramePair&)>& on_pair,
                       tools::InProcessGraph& graph) {
  StageDescriptor d;
  d.type = kLookerType;
  d.summary = "hands each ToF intensity and colour pair to tilth calibrate capture";
  d.inputs = {PortSpec::of<RawTofFrame>("intensity", "the ToF camera's intensity, 16 bits"),
              PortSpec::of<ColorImage>("color", "the colour image taken with it")};
  d.concurrency = Concurrency::kSerial;
  d.create = [&on_pair, &graph](const StageContext&) {
    return std::make_unique<PairLooker>(on_pair, graph);
  };
  return d;
}

void add_recording(tools::InProcessGraph& graph, const std::filesystem::path& recording) {
  graph.add_node("recording", "recording.image_folder",
                 {{"path", recording.string()}, {"on_missing", "stop"}});
  graph.add_edge("recording.raw", "look.intensity");
  graph.add_edge("recording.color", "look.color");
  graph.set_runtime({4, FullPolicy::kBlock, ErrorPolicy::kStop});
}

void add_cameras(tools::InProcessGraph& graph, const LiveCameras& cameras) {
  graph.add_node("tof", "aravis.tof_camera",
                 {{"camera", cameras.tof}, {"component", "Intensity"}, {"pixel_format", "Mono16"}});
  graph.add_node("color", "aravis.color_camera", {{"camera", cameras.color}});
  graph.add_node("pair", "pairing.depth_color");
  graph.add_edge("tof.raw", "pair.depth");
  graph.add_edge("tof.status", "pair.depth_status");
  graph.add_edge("color.color", "pair.color");
  graph.add_edge("color.status", "pair.color_status");
  graph.add_edge("pair.depth", "look.intensity");
  graph.add_edge("pair.color", "look.color");
  // The board search takes longer than a frame period: pairs that arrive meanwhile are
  // dropped, never the cameras' buffers held.
  graph.set_runtime({2, FullPolicy::kDropOldest, ErrorPolicy::kSkipFrame});
}

}  // namespace

RunResult look_at_pairs(const PairStream& stream,
                        const std::function<bool(const FramePair&)>& on_pair) {
  tools::InProcessGraph graph(kProgram);
  graph.add_stage_type(looker(on_pair, graph));
  graph.add_node("look", kLookerType);
  if (const auto* recording = std::get_if<std::filesystem::path>(&stream.source)) {
    add_recording(graph, *recording);
  } else {
    add_cameras(graph, std::get<LiveCameras>(stream.source));
  }
  for (const NodeSetting& setting : stream.settings) {
    graph.set_from_option(setting.node, setting.param, setting.option, setting.value);
  }
  RunResult result = graph.run(RunLimits{stream.max_frames});
  if (result.failed) throw Error(result.failure);
  return result;
}

}  // namespace tilth::calibrate
