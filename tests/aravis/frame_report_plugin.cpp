// aravistest.frame_report: one JSON line per frame on standard output, for the tests that
// run camera graphs with `tilth run`: the capture identity, the image (size, format,
// whether it is the simulator's test image for its block id) and the camera status.
#include <cstdio>
#include <mutex>

#include <nlohmann/json.hpp>

#include "fake_pattern.h"
#include "tilth/messages/camera_status.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace {

using nlohmann::json;

json describe_image(const tilth::Packet& packet) {
  if (packet.empty()) return nullptr;
  const std::uint64_t block = packet.info().frame_id;
  json image;
  if (packet.message()->type_name() == tilth::RawTofFrame::kTypeName) {
    const auto& raw = packet.get<tilth::RawTofFrame>();
    image = {{"cols", raw.gray.cols},
             {"rows", raw.gray.rows},
             {"format", "raw"},
             {"test_image", tilth::testing::matches_fake_mono16(raw.gray, block)}};
  } else {
    const auto& color = packet.get<tilth::ColorImage>();
    json test_image = nullptr;
    if (color.format == tilth::PixelFormat::kMono8) {
      test_image = tilth::testing::matches_fake_mono8(color.pixels, block);
    } else if (tilth::channels(color.format) == 1) {
      test_image = tilth::testing::matches_fake_bayer(color.pixels);
    }
    image = {{"cols", color.pixels.cols},
             {"rows", color.pixels.rows},
             {"format", tilth::to_string(color.format)},
             {"test_image", test_image}};
  }
  return image;
}

class FrameReport final : public tilth::Sink {
 public:
  explicit FrameReport(const tilth::StageContext& context)
      : label_(context.params.string("label")) {}

  void consume(const tilth::Frame& frame) override {
    const auto& status = frame.input<tilth::CameraStatus>(kStatus);
    const json line = {
        {"label", label_},
        {"frame_id", frame.info().frame_id},
        {"device_ns", frame.info().device_timestamp_ns},
        {"host_ns", frame.info().host_timestamp_ns},
        {"image", describe_image(frame.input(kImage))},
        {"streaming", status.streaming},
        {"problem", status.problem},
        {"completed", status.completed},
        {"incomplete", status.incomplete},
        {"lost", status.lost},
        {"late", status.late},
    };
    const std::string text = line.dump() + "\n";
    static std::mutex stdout_mutex;  // every report sink of the process writes whole lines
    std::lock_guard lock(stdout_mutex);
    std::fwrite(text.data(), 1, text.size(), stdout);
    std::fflush(stdout);
  }

 private:
  enum Port { kImage = 0, kStatus = 1 };
  const std::string label_;
};

tilth::StageDescriptor describe() {
  tilth::StageDescriptor d;
  d.type = "aravistest.frame_report";
  d.summary = "one JSON line per camera frame: identity, image check, status";
  d.inputs = {tilth::PortSpec::any("image", "a RawTofFrame or ColorImage").optional(),
              tilth::PortSpec::of<tilth::CameraStatus>("status", "the camera's status")};
  d.params = {tilth::ParamSpec::string("label", "").describe("names the camera in each line")};
  d.create = tilth::factory<FrameReport>();
  return d;
}

}  // namespace

TILTH_PLUGIN("aravistest")
TILTH_STAGE(describe());
