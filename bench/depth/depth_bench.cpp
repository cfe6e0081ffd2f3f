// depth.projection on one core: a 640x480 raw ToF frame of the paper's rig to depth.
#include <algorithm>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "projection.h"
#include "source_tree.h"
#include "tilth/frame.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/stage_params.h"

namespace tilth::depth {
namespace {

void BM_DepthProjection(benchmark::State& state) {
  const std::string calibration = testing::paper_rig_path().string();
  const StageDescriptor descriptor = describe_projection();
  const StageContext context{"projection",
                             stage_params(descriptor, {{"calibration", calibration}}),
                             Logger("projection"),
                             {}};
  const std::unique_ptr<Stage> stage = descriptor.create(context);
  auto& projection = dynamic_cast<Transform&>(*stage);

  // Soil at about 518 mm (gray 23666) with 1 mm of range noise (synthetic.tof_plane's
  // default) and 2 % of pixels without a measurement, so that both sides of the per-pixel
  // select are taken.
  RawTofFrame raw;
  raw.gray.create(480, 640, CV_16UC1);
  cv::randn(raw.gray, 23666, 44);
  cv::Mat dropouts(raw.gray.size(), CV_8UC1);
  cv::randu(dropouts, 0, 100);
  raw.gray.setTo(0, dropouts < 2);
  const Packet input(FrameInfo{}, std::make_shared<const RawTofFrame>(raw));

  for (auto _ : state) {
    std::vector<Packet> outputs(1);
    Frame frame(FrameInfo{}, std::span<const Packet>(&input, 1), outputs);
    projection.process(frame);
    benchmark::DoNotOptimize(outputs[0].message().get());
  }
  state.SetItemsProcessed(state.iterations());
}

// The machine is shared: the fastest repetition is the stage's own cost, the median
// what it gets under the current load.
double fastest(const std::vector<double>& times) {
  return *std::min_element(times.begin(), times.end());
}

BENCHMARK(BM_DepthProjection)->Unit(benchmark::kMillisecond)->ComputeStatistics("min", fastest);

}  // namespace
}  // namespace tilth::depth
