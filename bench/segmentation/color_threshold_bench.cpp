// The residue segmentations on a 640x480 frame (the blaze-101's grid) of straw and soil,
// in ms per frame: segmentation.color_threshold per colour space and dilation, and the
// variants with their defaults; pixel_classifier with the model that TILTH_BENCH_MODEL
// names (a file of tilth train-segmenter), skipped without one, on the whole frame and in
// the middle half the measurement chain segments; cnn likewise with the ONNX file that
// TILTH_BENCH_CNN names (tilth train-segmenter --model cnn), one core (cv::setNumThreads(0):
// OpenCV's dnn runs its layers on this thread alone).
#include <cstdlib>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "color_threshold.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/testing/stage_harness.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

// Straw (470 mm) and soil (500 mm) in random 8x8 blocks with colour and 2 mm depth noise,
// 2 % of the pixels without colour: the mask has many edges for the dilation to grow.
std::vector<std::shared_ptr<const Message>> straw_and_soil_frame() {
  const cv::Size size(640, 480);
  cv::RNG random(1);
  auto color = std::make_shared<RegisteredColor>();
  color->bgr.create(size, CV_8UC3);
  color->status.create(size, CV_8UC1);
  auto depth = std::make_shared<DepthImage>();
  depth->mm.create(size, CV_32FC1);
  cv::Mat blocks(size.height / 8, size.width / 8, CV_8UC1);
  random.fill(blocks, cv::RNG::UNIFORM, 0, 2);
  for (int v = 0; v < size.height; ++v) {
    for (int u = 0; u < size.width; ++u) {
      const bool straw = blocks.at<std::uint8_t>(v / 8, u / 8) != 0;
      const cv::Vec3d base = straw ? cv::Vec3d(120, 190, 220) : cv::Vec3d(55, 80, 110);
      cv::Vec3b& bgr = color->bgr.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c)
        bgr[c] = cv::saturate_cast<std::uint8_t>(base[c] + random.gaussian(8));
      const bool no_color = random.uniform(0.0, 1.0) < 0.02;
      color->status.at<std::uint8_t>(v, u) =
          no_color ? RegisteredColor::kOutsideColor : RegisteredColor::kValid;
      depth->mm.at<float>(v, u) = static_cast<float>((straw ? 470.0 : 500.0) + random.gaussian(2));
    }
  }
  return {color, depth};
}

void color_threshold(benchmark::State& state, const char* color_space) {
  testing::TransformHarness stage(describe_color_threshold(),
                                  {{"color_space", color_space}, {"dilation_px", state.range(0)}});
  const auto frame = straw_and_soil_frame();
  for (auto _ : state) benchmark::DoNotOptimize(stage.run(frame));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(color_threshold, hsv, "hsv")
    ->Arg(0)
    ->Arg(2)
    ->Arg(5)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(color_threshold, lab, "lab")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(color_threshold, bgr, "bgr")
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void variant(benchmark::State& state, StageDescriptor (*describe)()) {
  testing::TransformHarness stage(describe(), nlohmann::json::object());
  const auto frame = straw_and_soil_frame();
  for (auto _ : state) benchmark::DoNotOptimize(stage.run(frame));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(variant, color_index, describe_color_index)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(variant, lab_clusters, describe_lab_clusters)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(variant, depth_aided, describe_depth_aided)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(variant, fusion, describe_fusion)->Unit(benchmark::kMillisecond)->UseRealTime();

// `roi`: the whole frame (null), or the middle half that the measurement chain segments.
void pixel_classifier(benchmark::State& state, const nlohmann::json& roi) {
  const char* model = std::getenv("TILTH_BENCH_MODEL");
  if (model == nullptr) {
    state.SkipWithError("TILTH_BENCH_MODEL names no model file (tilth train-segmenter --out)");
    return;
  }
  testing::TransformHarness stage(describe_pixel_classifier(), {{"model", model}, {"roi", roi}});
  const auto frame = straw_and_soil_frame();
  for (auto _ : state) benchmark::DoNotOptimize(stage.run(frame));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(pixel_classifier, whole, nlohmann::json())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(pixel_classifier, middle_half, nlohmann::json("middle_half"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void cnn(benchmark::State& state, const nlohmann::json& roi) {
  const char* model = std::getenv("TILTH_BENCH_CNN");
  if (model == nullptr) {
    state.SkipWithError("TILTH_BENCH_CNN names no ONNX file (tilth train-segmenter --model cnn)");
    return;
  }
  cv::setNumThreads(0);
  testing::TransformHarness stage(describe_cnn(), {{"model", model}, {"roi", roi}});
  const auto frame = straw_and_soil_frame();
  for (auto _ : state) benchmark::DoNotOptimize(stage.run(frame));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(cnn, whole, nlohmann::json())->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(cnn, middle_half, nlohmann::json("middle_half"))
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace tilth::segmentation
