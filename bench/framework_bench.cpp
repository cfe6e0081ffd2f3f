// The runtime's own cost: per frame through whole graphs of trivial stages, and its
// building blocks. Stage costs are measured by each stage family's benchmarks.
#include <benchmark/benchmark.h>

#include "framework/graph_loader.h"
#include "framework/keyed_join.h"
#include "framework/latency_histogram.h"
#include "framework/runtime.h"
#include "temp_dir.h"
#include "test_stages.h"

namespace tilth {
namespace {

// frames/s through source -> N parallel no-op stages joined pairwise -> sink.
void BM_RuntimeFramesThroughChain(benchmark::State& state) {
  const auto frames = state.range(0);
  const auto in_flight = state.range(1);
  testing::TempDir dir;
  const auto file = dir.write("g.json", R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": )" +
                                            std::to_string(frames) + R"(}},
              "a": {"type": "test.delay"}, "b": {"type": "test.delay"},
              "sum": {"type": "test.add"}, "out": {"type": "test.record"}},
    "edges": [["src.out", "a.in"], ["src.out", "b.in"], ["a.out", "sum.a"], ["b.out", "sum.b"],
              ["sum.sum", "out.in"]],
    "runtime": {"max_in_flight": )" + std::to_string(in_flight) +
                                            R"(, "when_full": "block"}
  })");
  StageRegistry registry;
  testing::register_test_stages(registry);
  const GraphSpec spec = load_graph(file);
  for (auto _ : state) {
    testing::reset_sink_logs();
    Runtime runtime(validate_graph(spec, registry), registry);
    const RunResult result = runtime.run();
    benchmark::DoNotOptimize(result.metrics.frames_completed);
  }
  state.SetItemsProcessed(state.iterations() * frames);
}
BENCHMARK(BM_RuntimeFramesThroughChain)
    ->Args({2000, 1})
    ->Args({2000, 4})
    ->Args({2000, 16})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_KeyedJoinTwoInputs(benchmark::State& state) {
  KeyedJoin join(2);
  auto bundle = std::make_shared<const Bundle>();
  std::uint64_t sequence = 0;
  for (auto _ : state) {
    join.add(sequence, 0, bundle);
    benchmark::DoNotOptimize(join.add(sequence, 1, bundle));
    ++sequence;
  }
}
BENCHMARK(BM_KeyedJoinTwoInputs);

void BM_LatencyHistogramRecord(benchmark::State& state) {
  LatencyHistogram histogram;
  std::int64_t value = 1000;
  for (auto _ : state) {
    histogram.record(value);
    value = (value * 1103515245 + 12345) % 100'000'000;
  }
}
BENCHMARK(BM_LatencyHistogramRecord);

}  // namespace
}  // namespace tilth
