#include "registered_recording.h"

#include "in_process_graph.h"
#include "tilth/error.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/stage_descriptor.h"

namespace tilth::calibrate {
namespace {

constexpr const char* kProgram = "tilth calibrate check";
constexpr const char* kCollectorType = "calibrate.registered_frames";
// Far beyond any scene: no point is ever occluded.
constexpr double kNoOcclusionMm = 1e9;

class FrameCollector final : public Sink {
 public:
  enum Port { kDepth = 0, kColor = 1 };

  explicit FrameCollector(const std::function<void(const RegisteredFrame&)>& on_frame)
      : on_frame_(on_frame) {}

  void consume(const Frame& frame) override {
    const auto& depth = frame.input<DepthImage>(kDepth);
    const auto& color = frame.input<RegisteredColor>(kColor);
    on_frame_({frame.info().frame_id, depth.mm, color.bgr, color.status});
  }

 private:
  const std::function<void(const RegisteredFrame&)>& on_frame_;
};

StageDescriptor collector(const std::function<void(const RegisteredFrame&)>& on_frame) {
  StageDescriptor d;
  d.type = kCollectorType;
  d.summary = "hands each frame's depth and registered colour to tilth calibrate check";
  d.inputs = {PortSpec::of<DepthImage>("depth", "mm from the mounting surface"),
              PortSpec::of<RegisteredColor>("color", "colour on the depth grid")};
  d.concurrency = Concurrency::kSerial;
  d.create = [&on_frame](const StageContext&) {
    return std::make_unique<FrameCollector>(on_frame);
  };
  return d;
}

}  // namespace

void replay_registered(const std::filesystem::path& recording, const ReplayOptions& options,
                       const std::function<void(const RegisteredFrame&)>& on_frame) {
  tools::InProcessGraph graph(kProgram);
  graph.add_stage_type(collector(on_frame));
  const std::string calibration = options.calibration ? options.calibration->string() : "";
  graph.add_node("recording", "recording.image_folder",
                 {{"path", recording.string()}, {"on_missing", "stop"}});
  graph.add_node("project", "depth.projection", {{"calibration", calibration}});
  graph.add_node("register", "registration.projective",
                 {{"calibration", calibration}, {"occlusion_tolerance_mm", kNoOcclusionMm}});
  graph.add_node("check", kCollectorType);
  graph.add_edge("recording.raw", "project.raw");
  graph.add_edge("recording.color", "register.color");
  graph.add_edge("project.depth", "register.depth");
  graph.add_edge("project.depth", "check.depth");
  graph.add_edge("register.color", "check.color");
  graph.set_runtime({4, FullPolicy::kBlock, ErrorPolicy::kStop});
  const RunResult result = graph.run(RunLimits{options.max_frames});
  if (result.failed) throw Error(result.failure);
  // A partial recording is not judged.
  if (result.stopped)
    throw Error(recording.string() + ": the check was stopped before its frames ended");
}

}  // namespace tilth::calibrate
