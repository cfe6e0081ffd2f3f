// registration.projective on one core, alone and after depth.projection: 640x480 depth,
// 1280x1024 colour (bgr8 or a Bayer mosaic), the paper's rig, soil at about 518 mm; and
// as graphs/fake-cameras.json runs it, the middle half of the depth image registered from
// the 736x512 window of a Bayer sensor that `tilth calibrate color-window` gives.
#include <algorithm>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "projection.h"
#include "projective.h"
#include "row_kernels.h"
#include "source_tree.h"
#include "tilth/frame.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/stage_params.h"

namespace tilth::registration {
namespace {

const std::string kCalibration = testing::paper_rig_path().string();

// A stage with its defaults, the shipped calibration and `params`.
std::unique_ptr<Stage> make(const StageDescriptor& descriptor, nlohmann::json params) {
  params["calibration"] = kCalibration;
  return descriptor.create(
      StageContext{descriptor.type, stage_params(descriptor, params), Logger(descriptor.type), {}});
}

std::shared_ptr<const Message> run(Stage& stage, std::span<const Packet> inputs) {
  std::vector<Packet> outputs(1);
  Frame frame(FrameInfo{}, inputs, outputs);
  dynamic_cast<Transform&>(stage).process(frame);
  return outputs[0].message();
}

// Raw ToF frame of soil at about 518 mm with 1 mm of range noise (synthetic.tof_plane's
// default) and 2 % dropouts.
Packet raw_frame() {
  RawTofFrame raw;
  raw.gray.create(480, 640, CV_16UC1);
  cv::randn(raw.gray, 23666, 44);
  cv::Mat dropouts(raw.gray.size(), CV_8UC1);
  cv::randu(dropouts, 0, 100);
  raw.gray.setTo(0, dropouts < 2);
  return Packet(FrameInfo{}, std::make_shared<const RawTofFrame>(std::move(raw)));
}

Packet color_frame(PixelFormat format, const cv::Rect& window = {0, 0, 1280, 1024}) {
  ColorImage color;
  color.format = format;
  color.pixels.create(window.size(), CV_8UC(channels(format)));
  if (window.tl() != cv::Point()) color.sensor_offset = window.tl();
  cv::randu(color.pixels, 0, 256);
  return Packet(FrameInfo{}, std::make_shared<const ColorImage>(std::move(color)));
}

const char* interpolation_name(std::int64_t bilinear) { return bilinear ? "bilinear" : "nearest"; }

// The stage's parameters for the arguments: pixel format (ignored), bilinear (0/1), the
// index of the instruction-set level among those the CPU runs.
nlohmann::json registration_params(const benchmark::State& state) {
  return {{"occlusion_tolerance_mm", 10.0},
          {"interpolation", interpolation_name(state.range(1))},
          {"instruction_set", available_row_kernels()[state.range(2)]->level}};
}

std::string label(const benchmark::State& state) {
  return std::string(to_string(static_cast<PixelFormat>(state.range(0)))) + ", " +
         interpolation_name(state.range(1)) + ", " + available_row_kernels()[state.range(2)]->level;
}

// Args: see registration_params.
void BM_Registration(benchmark::State& state) {
  cv::setNumThreads(0);  // one core: OpenCV's own threads (demosaicing) off too
  const auto format = static_cast<PixelFormat>(state.range(0));
  const auto projection = make(depth::describe_projection(), nlohmann::json::object());
  const auto registration = make(describe_projective(), registration_params(state));
  const Packet raw = raw_frame();
  const std::vector<Packet> inputs = {
      Packet(FrameInfo{}, run(*projection, std::span<const Packet>(&raw, 1))), color_frame(format)};
  for (auto _ : state) benchmark::DoNotOptimize(run(*registration, inputs).get());
  state.SetLabel(label(state));
}

// Args: see registration_params.
void BM_ProjectionAndRegistration(benchmark::State& state) {
  cv::setNumThreads(0);
  const auto format = static_cast<PixelFormat>(state.range(0));
  const auto projection = make(depth::describe_projection(), nlohmann::json::object());
  const auto registration = make(describe_projective(), registration_params(state));
  const Packet raw = raw_frame();
  std::vector<Packet> inputs = {Packet(), color_frame(format)};
  for (auto _ : state) {
    inputs[0] = Packet(FrameInfo{}, run(*projection, std::span<const Packet>(&raw, 1)));
    benchmark::DoNotOptimize(run(*registration, inputs).get());
    inputs[0] = Packet();  // the depth image goes back to its pool
  }
  state.SetLabel(label(state));
}

// The region and colour window of graphs/fake-cameras.json, nearest sampling of a Bayer
// mosaic, the widest instruction set.
void BM_RegistrationOfWindow(benchmark::State& state) {
  cv::setNumThreads(0);
  const auto projection = make(depth::describe_projection(), nlohmann::json::object());
  const auto registration =
      make(describe_projective(), {{"roi", "middle_half"}, {"interpolation", "nearest"}});
  const Packet raw = raw_frame();
  const std::vector<Packet> inputs = {
      Packet(FrameInfo{}, run(*projection, std::span<const Packet>(&raw, 1))),
      color_frame(PixelFormat::kBayerRggb8, {368, 256, 736, 512})};
  for (auto _ : state) benchmark::DoNotOptimize(run(*registration, inputs).get());
}

void formats(benchmark::internal::Benchmark* b) {
  for (const auto format : {PixelFormat::kBgr8, PixelFormat::kBayerRggb8}) {
    for (const int bilinear : {0, 1}) {
      for (std::size_t level = 0; level < available_row_kernels().size(); ++level) {
        b->Args({static_cast<int>(format), bilinear, static_cast<std::int64_t>(level)});
      }
    }
  }
}

// The machine is shared: the fastest repetition is the stage's own cost, the median
// what it gets under the current load.
double fastest(const std::vector<double>& times) {
  return *std::min_element(times.begin(), times.end());
}

BENCHMARK(BM_Registration)
    ->Apply(formats)
    ->Unit(benchmark::kMillisecond)
    ->ComputeStatistics("min", fastest);
BENCHMARK(BM_RegistrationOfWindow)
    ->Unit(benchmark::kMillisecond)
    ->ComputeStatistics("min", fastest);
BENCHMARK(BM_ProjectionAndRegistration)
    ->Apply(formats)
    ->Unit(benchmark::kMillisecond)
    ->ComputeStatistics("min", fastest);

}  // namespace
}  // namespace tilth::registration
