// The measurement chain on one core: its four nodes (project -> register -> segment ->
// estimate) with the types and parameters of graphs/measurement-chain.json (or of the
// chain file TILTH_CHAIN_GRAPH names) and the paper's rig, on one frame pair (640x480
// depth, 1280x1024 colour) rendered by synthetic.scene (preset case_c), in ms per frame
// pair, frame after frame and at the cameras' 30 frames/s; and each stage alone on the
// same frame.
//
// allocs_per_frame counts the heap allocations of a frame in the steady state: global
// operator new / new[] (replaced below) and cv::Mat buffers (which OpenCV takes from
// malloc, not operator new; counted by a Mat allocator installed for the run).
#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <map>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "framework/graph_loader.h"
#include "framework/stage_registry.h"
#include "source_tree.h"
#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/stage_params.h"

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

const std::string kCalibration = testing::paper_rig_path().string();

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
  if (descriptor.param("calibration") != nullptr) params["calibration"] = kCalibration;
  return registry().create(type,
                           StageContext{type, stage_params(descriptor, params), Logger(type), {}});
}

// The node `name` of the chain file as the graph loader reads it (variables substituted),
// its parameters completed as `make` does.
StageInstance chain_node(const std::string& name) {
  static const GraphSpec chain = [] {
    const char* const chosen = std::getenv("TILTH_CHAIN_GRAPH");
    return load_graph(chosen ? std::filesystem::path(chosen)
                             : testing::source_path("graphs/measurement-chain.json"));
  }();
  for (const NodeSpec& node : chain.nodes) {
    if (node.name != name) continue;
    nlohmann::json params = nlohmann::json::object();
    for (const auto& [key, param] : node.params) params[key] = param.value;
    return make(node.type, params);
  }
  throw std::runtime_error("the chain file has no node '" + name + "'");
}

// One frame pair (raw ToF, colour) of the simulator's case_c in `color_format`, rendered
// once per format.
const std::array<Packet, 2>& scene_frame(const std::string& color_format) {
  static std::map<std::string, std::array<Packet, 2>> rendered;
  if (const auto found = rendered.find(color_format); found != rendered.end()) {
    return found->second;
  }
  StageInstance scene =
      make("synthetic.scene", {{"preset", "case_c"}, {"color_format", color_format}});
  std::vector<Packet> outputs(3);
  Frame frame(FrameInfo{}, {}, outputs);
  dynamic_cast<Source&>(*scene.stage).produce(frame);
  return rendered[color_format] = {outputs[0], outputs[1]};
}

void process(StageInstance& stage, std::span<const Packet> inputs, std::span<Packet> outputs) {
  Frame frame(FrameInfo{}, inputs, outputs);
  dynamic_cast<Transform&>(*stage.stage).process(frame);
}

// The four stages of the chain file, and the packets of
// one frame, held here so that running a frame itself allocates nothing.
class Chain {
 public:
  enum Step { kProject, kRegister, kSegment, kEstimate, kWhole };

  explicit Chain(const char* color_format) : pair_(scene_frame(color_format)) {}

  // One stage, or the whole chain, on the frame pair. A stage alone reads the outputs
  // of the stages before it from the last whole run.
  void run(Step step) {
    if (step == kProject || step == kWhole) process(project_, std::span(&pair_[0], 1), depth_);
    if (step == kRegister || step == kWhole) {
      register_in_ = {depth_[0], pair_[1]};
      process(register_, register_in_, registered_);
    }
    if (step == kSegment || step == kWhole) {
      segment_in_ = {registered_[0], depth_[0]};
      process(segment_, segment_in_, segmented_);
    }
    if (step == kEstimate || step == kWhole) {
      estimate_in_ = {segmented_[1], registered_[0]};  // the soil depth, and the colour checked
      process(estimate_, estimate_in_, distance_);
      benchmark::DoNotOptimize(distance_[0].message().get());
    }
    // A stage's outputs (every message, for the whole chain) go back to its pool before
    // the next frame.
    const auto release = [](std::span<Packet> packets) {
      std::fill(packets.begin(), packets.end(), Packet());
    };
    if (step == kWhole) {
      for (const std::span<Packet> packets :
           {std::span<Packet>(depth_), std::span<Packet>(register_in_),
            std::span<Packet>(registered_), std::span<Packet>(segment_in_),
            std::span<Packet>(segmented_), std::span<Packet>(estimate_in_),
            std::span<Packet>(distance_)}) {
        release(packets);
      }
    } else if (step == kEstimate) {
      release(distance_);
    }
  }

 private:
  StageInstance project_ = chain_node("project");
  StageInstance register_ = chain_node("register");
  StageInstance segment_ = chain_node("segment");
  StageInstance estimate_ = chain_node("estimate");
  const std::array<Packet, 2> pair_;
  std::array<Packet, 1> depth_;
  std::array<Packet, 2> register_in_;
  std::array<Packet, 1> registered_;
  std::array<Packet, 2> segment_in_;
  std::array<Packet, 2> segmented_;
  std::array<Packet, 2> estimate_in_;
  std::array<Packet, 1> distance_;
};

// `idle`: how long the core waits, untimed, before each frame.
void run(benchmark::State& state, const char* color_format, Chain::Step step,
         std::chrono::microseconds idle = std::chrono::microseconds(0)) {
  cv::setNumThreads(0);  // one core: OpenCV's own threads (demosaicing, cvtColor) off too
  Chain chain(color_format);
  for (int warm_up = 0; warm_up < 3; ++warm_up) chain.run(Chain::kWhole);
  if (step != Chain::kWhole) {
    // Keep the inputs of the measured stage: run the chain up to it once more. Then the
    // stage twice: its output is held from one frame to the next, so its pool needs a
    // second message, made here rather than in the measured loop.
    for (int before = Chain::kProject; before < step; ++before) {
      chain.run(static_cast<Chain::Step>(before));
    }
    chain.run(step);
    chain.run(step);
  }

  CountingMatAllocator counting;
  cv::MatAllocator* const previous = cv::Mat::getDefaultAllocator();
  cv::Mat::setDefaultAllocator(&counting);
  const std::int64_t before = allocations.load();
  for (auto _ : state) {
    if (idle.count() > 0) {
      state.PauseTiming();
      std::this_thread::sleep_for(idle);
      state.ResumeTiming();
    }
    chain.run(step);
  }
  const std::int64_t counted = allocations.load() - before;
  cv::Mat::setDefaultAllocator(previous);

  state.counters["allocs_per_frame"] =
      static_cast<double>(counted) / static_cast<double>(state.iterations());
  state.SetLabel(color_format);
}

void chain(benchmark::State& state, const char* color_format) {
  run(state, color_format, Chain::kWhole);
}
// The whole chain at the cameras' pace: the core idles for a frame period between two
// frames, as under `tilth run` at 30 frames/s, and the frame finds colder caches.
void chain_at_30fps(benchmark::State& state, const char* color_format) {
  run(state, color_format, Chain::kWhole, std::chrono::microseconds(33333));
}
void project(benchmark::State& state, const char* color_format) {
  run(state, color_format, Chain::kProject);
}
void register_color(benchmark::State& state, const char* color_format) {
  run(state, color_format, Chain::kRegister);
}
void segment(benchmark::State& state, const char* color_format) {
  run(state, color_format, Chain::kSegment);
}
void estimate(benchmark::State& state, const char* color_format) {
  run(state, color_format, Chain::kEstimate);
}

// The machine is shared: the fastest repetition is the chain's own cost, the median
// what it gets under the current load.
double fastest(const std::vector<double>& times) {
  return *std::min_element(times.begin(), times.end());
}

#define TILTH_CHAIN_BENCHMARK(function, format) \
  BENCHMARK_CAPTURE(function, format, #format)  \
      ->Unit(benchmark::kMillisecond)           \
      ->ComputeStatistics("min", fastest)

TILTH_CHAIN_BENCHMARK(chain, bgr8);
TILTH_CHAIN_BENCHMARK(chain, bayer_rggb8);
TILTH_CHAIN_BENCHMARK(chain_at_30fps, bayer_rggb8)->Iterations(90);
TILTH_CHAIN_BENCHMARK(project, bgr8);
TILTH_CHAIN_BENCHMARK(register_color, bgr8);
TILTH_CHAIN_BENCHMARK(register_color, bayer_rggb8);
TILTH_CHAIN_BENCHMARK(segment, bgr8);
TILTH_CHAIN_BENCHMARK(estimate, bgr8);

}  // namespace
}  // namespace tilth
