// The ground estimators on a 640x480 soil-depth frame (the blaze-101's grid): a tilted
// plane with 1 mm noise, 20 % outliers and 40 % of the pixels masked as residue, in ms
// per frame.
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "estimators.h"
#include "source_tree.h"
#include "synthetic_ground.h"
#include "tilth/messages/depth_image.h"
#include "tilth/testing/stage_harness.h"

namespace tilth::estimation {
namespace {

const std::string kPaperRig = testing::paper_rig_path().string();

std::vector<std::shared_ptr<const Message>> soil_frame() {
  testing::GroundScene scene;
  scene.tilt_x_deg = 5.0;
  scene.tilt_y_deg = 3.0;
  scene.noise_mm = 1.0;
  scene.outlier_fraction = 0.2;
  auto depth = std::make_shared<DepthImage>();
  depth->mm = testing::render(scene, load_calibration(kPaperRig).depth);
  cv::Mat residue(depth->mm.size(), CV_8UC1);
  cv::RNG(2).fill(residue, cv::RNG::UNIFORM, 0, 100);
  depth->mm.setTo(std::numeric_limits<float>::quiet_NaN(), residue < 40);
  return {depth};
}

void run(benchmark::State& state, testing::TransformHarness& stage) {
  const auto frame = soil_frame();
  for (auto _ : state) benchmark::DoNotOptimize(stage.run(frame));
  state.counters["frames/s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void ground_distance(benchmark::State& state, const char* statistic) {
  testing::TransformHarness stage(describe_ground_distance(), {{"statistic", statistic}});
  run(state, stage);
}

void ground_plane(benchmark::State& state) {
  testing::TransformHarness stage(describe_ground_plane(),
                                  {{"calibration", kPaperRig}, {"stride", state.range(0)}});
  run(state, stage);
}

BENCHMARK_CAPTURE(ground_distance, median, "median")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(ground_distance, trimmed_mean, "trimmed_mean")
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(ground_plane)->Arg(4)->Arg(2)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tilth::estimation
