// The measurement chain on one core: depth.projection -> registration.projective ->
// segmentation.color_threshold -> estimation.ground_distance, default parameters and the
// paper's rig, on one frame pair (640x480 depth, 1280x1024 colour) rendered by
// synthetic.scene (preset case_c), in ms per frame pair.
//
// allocs_per_frame counts the heap allocations of a frame in the steady state: global
// operator new / new[] (replaced below) and cv::Mat buffers (which OpenCV takes from
// malloc, not operator new; counted by a Mat allocator installed for the run).
#include <algorithm>
#include <array>
#include <atomic>
#include <cstdlib>
#include <new>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "framework/stage_registry.h"
#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_distance.h"

namespace {

std::atomic<std::int64_t> allocations{0};

void* counted_allocation(std::size_t size) {
  allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}

}  // namespace

void* operator new(std::size_t size) { return counted_allocation(size); }
void* operator new[](std::size_t size) { return counted_allocation(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace tilth {
namespace {

const std::string kCalibration = TILTH_SOURCE_DIR "/calib/paper_rig.calib.json";

// OpenCV's own allocator, counting the image buffers it hands out.
class CountingMatAllocator final : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data, size_t* step,
                         cv::AccessFlag flags, cv::UMatUsageFlags usage) const override {
    allocations.fetch_add(1, std::memory_order_relaxed);
    return base_->allocate(dims, sizes, type, data, step, flags, usage);
  }
  bool allocate(cv::UMatData* data, cv::AccessFlag flags, cv::UMatUsageFlags usage) const override {
    return base_->allocate(data, flags, usage);
  }
  void deallocate(cv::UMatData* data) const override { base_->deallocate(data); }

 private:
  cv::MatAllocator* base_ = cv::Mat::getStdAllocator();
};

StageRegistry& registry() {
  static StageRegistry plugins = [] {
    StageRegistry loaded;
    std::istringstream files(TILTH_CHAIN_PLUGINS);
    for (std::string file; std::getline(files, file, ':');) loaded.load(file);
    return loaded;
  }();
  return plugins;
}

// A stage with its defaults, the shipped calibration where it takes one, and `params`.
StageInstance make(const std::string& type, nlohmann::json params = nlohmann::json::object()) {
  const auto& descriptor = registry().find(type)->descriptor;
  for (const auto& spec : descriptor.params) {
    if (!params.contains(spec.name)) params[spec.name] = spec.default_value;
  }
  if (params.contains("calibration")) params["calibration"] = kCalibration;
  return registry().create(type, StageContext{type, Params(params), Logger(type), {}});
}

// One frame pair (raw ToF, colour) of the simulator's case_c in `color_format`.
std::array<Packet, 2> scene_frame(const std::string& color_format) {
  StageInstance scene =
      make("synthetic.scene", {{"preset", "case_c"}, {"color_format", color_format}});
  std::vector<Packet> outputs(3);
  Frame frame(FrameInfo{}, {}, outputs);
  dynamic_cast<Source&>(*scene.stage).produce(frame);
  return {outputs[0], outputs[1]};
}

void process(StageInstance& stage, std::span<const Packet> inputs, std::span<Packet> outputs) {
  Frame frame(FrameInfo{}, inputs, outputs);
  dynamic_cast<Transform&>(*stage.stage).process(frame);
}

void chain(benchmark::State& state, const char* color_format) {
  cv::setNumThreads(0);  // one core: OpenCV's own threads (demosaicing, cvtColor) off too
  StageInstance project = make("depth.projection");
  StageInstance reg = make("registration.projective");
  StageInstance segment = make("segmentation.color_threshold");
  StageInstance estimate = make("estimation.ground_distance");
  const std::array<Packet, 2> pair = scene_frame(color_format);

  // The packets of one frame, held here so that the loop itself allocates nothing.
  std::array<Packet, 1> depth;
  std::array<Packet, 2> register_in;
  std::array<Packet, 1> registered;
  std::array<Packet, 2> segment_in;
  std::array<Packet, 2> segmented;
  std::array<Packet, 1> distance;
  const auto run_frame = [&] {
    process(project, std::span(&pair[0], 1), depth);
    register_in = {depth[0], pair[1]};
    process(reg, register_in, registered);
    segment_in = {registered[0], depth[0]};
    process(segment, segment_in, segmented);
    process(estimate, std::span(&segmented[1], 1), distance);
    benchmark::DoNotOptimize(distance[0].message().get());
    // Every message back to its pool before the next frame.
    for (const std::span<Packet> packets :
         {std::span<Packet>(depth), std::span<Packet>(register_in), std::span<Packet>(registered),
          std::span<Packet>(segment_in), std::span<Packet>(segmented),
          std::span<Packet>(distance)}) {
      std::fill(packets.begin(), packets.end(), Packet());
    }
  };
  for (int warm_up = 0; warm_up < 3; ++warm_up) run_frame();

  CountingMatAllocator counting;
  cv::MatAllocator* const previous = cv::Mat::getDefaultAllocator();
  cv::Mat::setDefaultAllocator(&counting);
  const std::int64_t before = allocations.load();
  for (auto _ : state) run_frame();
  const std::int64_t counted = allocations.load() - before;
  cv::Mat::setDefaultAllocator(previous);

  state.counters["allocs_per_frame"] =
      static_cast<double>(counted) / static_cast<double>(state.iterations());
  state.SetLabel(color_format);
}

// The machine is shared: the fastest repetition is the chain's own cost, the median
// what it gets under the current load.
double fastest(const std::vector<double>& times) {
  return *std::min_element(times.begin(), times.end());
}

BENCHMARK_CAPTURE(chain, bgr8, "bgr8")
    ->Unit(benchmark::kMillisecond)
    ->ComputeStatistics("min", fastest);
BENCHMARK_CAPTURE(chain, bayer_rggb8, "bayer_rggb8")
    ->Unit(benchmark::kMillisecond)
    ->ComputeStatistics("min", fastest);

}  // namespace
}  // namespace tilth
