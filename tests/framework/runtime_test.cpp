// The runtime under concurrency: joining by frame, frame order at stateful stages and
// sinks, bounded frames in flight with both full-pipeline policies, errors, stop, data
// lost by a sink.
// Run under ThreadSanitizer by the tsan preset.
#include "framework/runtime.h"

#include <chrono>
#include <numeric>
#include <thread>

#include <gtest/gtest.h>

#include "framework/graph_loader.h"
#include "temp_dir.h"
#include "test_stages.h"

namespace tilth {
namespace {

using testing::sink_log;
using testing::TempDir;

class RuntimeTest : public ::testing::Test {
 protected:
  RuntimeTest() {
    testing::register_test_stages(registry_);
    testing::reset_sink_logs();
  }

  std::unique_ptr<Runtime> make(const std::string& text, RunLimits limits = {}) {
    const auto file = dir_.write("g.json", text);
    return std::make_unique<Runtime>(validate_graph(load_graph(file), registry_), registry_,
                                     limits);
  }
  RunResult run(const std::string& text, RunLimits limits = {}) {
    return make(text, limits)->run();
  }

  static std::vector<std::int64_t> values(const std::string& node) {
    std::vector<std::int64_t> result;
    for (const auto& frame : sink_log(node).frames) result.push_back(frame.value);
    return result;
  }
  static std::vector<std::uint64_t> sequences(const std::string& node) {
    std::vector<std::uint64_t> result;
    for (const auto& frame : sink_log(node).frames) result.push_back(frame.info.sequence);
    return result;
  }
  static std::vector<std::uint64_t> dense(std::size_t n) {
    std::vector<std::uint64_t> result(n);
    std::iota(result.begin(), result.end(), 0);
    return result;
  }
  static std::vector<std::int64_t> range(std::int64_t n, std::int64_t scale = 1,
                                         std::int64_t offset = 0) {
    std::vector<std::int64_t> result;
    for (std::int64_t i = 0; i < n; ++i) result.push_back(i * scale + offset);
    return result;
  }

  TempDir dir_;
  StageRegistry registry_;
};

// Two parallel branches with random delays re-join at an adder: every sum must pair
// the same frame's values (x+1 and x+100 -> 2x+101), and the sink sees frames in order.
TEST_F(RuntimeTest, JoinsByFrameAndDeliversInOrder) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 300}},
              "a": {"type": "test.delay", "params": {"add": 1, "max_delay_us": 2000}},
              "b": {"type": "test.delay", "params": {"add": 100, "max_delay_us": 500}},
              "sum": {"type": "test.add"},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "a.in"], ["src.out", "b.in"], ["a.out", "sum.a"], ["b.out", "sum.b"],
              ["sum.sum", "out.in"]],
    "runtime": {"max_in_flight": 16, "when_full": "block"}
  })");
  EXPECT_FALSE(result.failed);
  EXPECT_EQ(values("out"), range(300, 2, 101));
  EXPECT_EQ(sequences("out"), dense(300));
  EXPECT_EQ(result.metrics.frames_completed, 300u);
  EXPECT_EQ(result.metrics.frames_dropped, 0u);
  EXPECT_TRUE(sink_log("out").finished);
  // Parallel stages did run frames concurrently (16 in flight, up to 2 ms each).
  EXPECT_GE(testing::max_parallel_delays(), 2);
}

TEST_F(RuntimeTest, SinksRunSeriallyAndInOrderBehindAParallelStage) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 200}},
              "d": {"type": "test.delay", "params": {"max_delay_us": 1000}},
              "out": {"type": "test.record", "params": {"delay_us": 50}}},
    "edges": [["src.out", "d.in"], ["d.out", "out.in"]],
    "runtime": {"max_in_flight": 8}
  })");
  EXPECT_EQ(values("out"), range(200));
  EXPECT_EQ(sink_log("out").max_concurrent.load(), 1);
  EXPECT_EQ(result.metrics.frames_completed, 200u);
}

// With `block`, a slow sink holds the source back and nothing is lost, whatever the
// in-flight limit.
TEST_F(RuntimeTest, BlockPolicyLosesNothing) {
  for (int limit : {1, 3}) {
    testing::reset_sink_logs();
    const RunResult result = run(R"({
      "nodes": {"src": {"type": "test.counter", "params": {"count": 100}},
                "out": {"type": "test.record", "params": {"delay_us": 200}}},
      "edges": [["src.out", "out.in"]],
      "runtime": {"max_in_flight": )" +
                                 std::to_string(limit) + R"(, "when_full": "block"}
    })");
    EXPECT_EQ(values("out"), range(100)) << "max_in_flight " << limit;
    EXPECT_EQ(result.metrics.frames_dropped, 0u);
  }
}

// With `drop_oldest`, a source faster than the sink loses frames at admission, never
// inside the graph: every admitted frame reaches the sink, in order, and the counts add
// up (produced = admitted + dropped + the one discarded when the stream ended).
TEST_F(RuntimeTest, DropOldestDropsAtAdmissionOnly) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 400, "period_us": 100}},
              "out": {"type": "test.record", "params": {"delay_us": 2000}}},
    "edges": [["src.out", "out.in"]],
    "runtime": {"max_in_flight": 2, "when_full": "drop_oldest"}
  })");
  const auto seen = values("out");
  EXPECT_GT(result.metrics.frames_dropped, 100u);
  EXPECT_EQ(seen.size(), result.metrics.frames_completed);
  EXPECT_EQ(result.metrics.frames_admitted, result.metrics.frames_completed);
  EXPECT_LE(result.metrics.frames_admitted + result.metrics.frames_dropped, 400u);
  EXPECT_GE(result.metrics.frames_admitted + result.metrics.frames_dropped, 399u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_EQ(sequences("out"), dense(seen.size()));
  // The freshest frame goes next: the last frame produced is the last one delivered.
  EXPECT_EQ(seen.back(), 399);
}

TEST_F(RuntimeTest, StageErrorSkipsTheFrameAndCarriesOn) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 20}},
              "f": {"type": "test.fail", "params": {"every": 5}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "f.in"], ["f.out", "out.in"]],
    "runtime": {"on_error": "skip"}
  })");
  EXPECT_FALSE(result.failed);
  const auto& frames = sink_log("out").frames;
  ASSERT_EQ(frames.size(), 20u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].skipped, i % 5 == 0) << "frame " << i;
    EXPECT_EQ(frames[i].info.frame_id, i);
  }
  EXPECT_EQ(result.metrics.stages[1].errors, 4u);
  EXPECT_EQ(result.metrics.stages[2].skipped, 4u);
  EXPECT_EQ(result.metrics.frames_completed, 20u);
}

TEST_F(RuntimeTest, StageErrorStopsTheGraphWhenAsked) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 0, "period_us": 1000}},
              "f": {"type": "test.fail", "params": {"every": 50}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "f.in"], ["f.out", "out.in"]],
    "runtime": {"on_error": "stop", "max_in_flight": 1}
  })");
  EXPECT_TRUE(result.failed);
  EXPECT_FALSE(result.stopped);  // not by stop()
  EXPECT_EQ(result.failure,
            "node 'f' (test.fail) failed on frame 0 (sequence 0): bad value 0; stopping "
            "(on_error: stop)");
  EXPECT_TRUE(sink_log("out").finished);
  EXPECT_LE(sink_log("out").frames.size(), 1u);
}

TEST_F(RuntimeTest, StopFinishesFramesInFlight) {
  auto runtime = make(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 0, "period_us": 500}},
              "d": {"type": "test.delay", "params": {"max_delay_us": 3000}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "d.in"], ["d.out", "out.in"]],
    "runtime": {"max_in_flight": 8}
  })");
  std::thread stopper([&] {
    // Stop mid-stream: once 20 frames have reached the sink.
    auto& log = sink_log("out");
    for (;;) {
      {
        std::lock_guard lock(log.mutex);
        if (log.frames.size() >= 20) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    runtime->stop();
  });
  const RunResult result = runtime->run();
  stopper.join();
  EXPECT_FALSE(result.failed);
  EXPECT_TRUE(result.stopped);
  const auto seen = values("out");
  EXPECT_GE(seen.size(), 20u);
  EXPECT_EQ(seen, range(static_cast<std::int64_t>(seen.size())));  // nothing lost
  EXPECT_EQ(result.metrics.frames_admitted, seen.size());
  EXPECT_EQ(result.metrics.frames_in_flight, 0u);
  EXPECT_TRUE(sink_log("out").finished);
}

// A sink that reports lost data is counted, per node, with its first report; the graph
// runs on and the other sinks get every frame.
TEST_F(RuntimeTest, LostDataIsCountedPerNodeAndTheGraphRunsOn) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 20}},
              "lossy": {"type": "test.lossy", "params": {"every": 3}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "lossy.in"], ["src.out", "out.in"]],
    "runtime": {"on_error": "stop"}
  })");
  EXPECT_FALSE(result.failed);
  EXPECT_FALSE(result.stopped);
  ASSERT_EQ(result.data_lost.size(), 1u);
  EXPECT_EQ(result.data_lost[0].node, "lossy");
  EXPECT_EQ(result.data_lost[0].type, "test.lossy");
  EXPECT_EQ(result.data_lost[0].frames, 7u);  // 0, 3, ..., 18
  EXPECT_EQ(result.data_lost[0].first, "value 0 not stored");
  EXPECT_EQ(values("out"), range(20));
  EXPECT_EQ(result.metrics.frames_completed, 20u);
}

TEST_F(RuntimeTest, FrameLimit) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 0}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "out.in"]]
  })",
                               RunLimits{25});
  EXPECT_EQ(values("out"), range(25));
  EXPECT_EQ(result.metrics.frames_completed, 25u);
}

TEST_F(RuntimeTest, MultipleSourcesJoinFrameByFrame) {
  run(R"({
    "nodes": {"a": {"type": "test.counter", "params": {"count": 50}},
              "b": {"type": "test.counter", "params": {"count": 60, "period_us": 100}},
              "sum": {"type": "test.add"},
              "out": {"type": "test.record"}},
    "edges": [["a.out", "sum.a"], ["b.out", "sum.b"], ["sum.sum", "out.in"]]
  })");
  EXPECT_EQ(values("out"), range(50, 2));  // ends with the shorter stream
}

// Two sources at their own pace (0,1,2,... fast; 0,2,4,... slow) meet at a synchronizer:
// only equal counts pair, the graph's frames are numbered densely from the pairs, and the
// stream ends with the last source.
TEST_F(RuntimeTest, SynchronizerLinesUpSourcesOnTheirOwnClocks) {
  const RunResult result = run(R"({
    "nodes": {"fast": {"type": "test.counter", "params": {"count": 50}},
              "slow": {"type": "test.counter", "params": {"count": 30, "step": 2,
                                                          "period_us": 200}},
              "pair": {"type": "test.pair_equal"},
              "d": {"type": "test.delay", "params": {"max_delay_us": 500}},
              "out": {"type": "test.record"}},
    "edges": [["fast.out", "pair.a"], ["slow.out", "pair.b"], ["pair.sum", "d.in"],
              ["d.out", "out.in"]],
    "runtime": {"max_in_flight": 4, "when_full": "block"}
  })");
  EXPECT_FALSE(result.failed) << result.failure;
  EXPECT_EQ(values("out"), range(25, 4));  // 2v for v = 0, 2, ..., 48
  EXPECT_EQ(sequences("out"), dense(25));
  std::vector<std::uint64_t> frame_ids;
  for (const auto& frame : sink_log("out").frames) frame_ids.push_back(frame.info.frame_id);
  EXPECT_EQ(frame_ids.back(), 48u);
  EXPECT_EQ(result.metrics.frames_admitted, 25u);
  EXPECT_EQ(result.metrics.stages[2].node, "pair");
  EXPECT_EQ(result.metrics.stages[2].latency.count, 80u);  // one accept() per source frame
}

TEST_F(RuntimeTest, EveryStageIsTimed) {
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter", "params": {"count": 40}},
              "d": {"type": "test.delay", "params": {"max_delay_us": 2000}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "d.in"], ["d.out", "out.in"]]
  })");
  ASSERT_EQ(result.metrics.stages.size(), 3u);
  EXPECT_EQ(result.metrics.stages[1].node, "d");
  EXPECT_EQ(result.metrics.stages[1].latency.count, 40u);
  // Delays are uniform in [0, 2) ms, mean 1 ms (the mean of 40 is below 0.5 ms with a
  // chance of 1e-8). A sleep never ends early, but on a loaded machine it may end much
  // later, so only the lower bound is a test of the timing.
  EXPECT_GT(result.metrics.stages[1].latency.mean_ms, 0.5);
  EXPECT_GE(result.metrics.stages[1].latency.p99_ms, result.metrics.stages[1].latency.p50_ms);
  EXPECT_EQ(result.metrics.end_to_end.count, 40u);
  EXPECT_GT(result.metrics.frames_per_second, 0.0);
}

// The live view's server answers status requests from its own thread as soon as its stage
// exists, while the runtime is still making the others (a segfault in CI once).
TEST_F(RuntimeTest, MetricsAskedForWhileStagesAreMadeAreEmpty) {
  const RunResult result = run(R"({
    "nodes": {"a_probe": {"type": "test.metrics_probe"},
              "src": {"type": "test.counter", "params": {"count": 3}}},
    "edges": [["src.out", "a_probe.in"]]
  })");
  EXPECT_EQ(sink_log("a_probe").stages_in_metrics_at_start, 0u);
  EXPECT_EQ(sink_log("a_probe").frames.size(), 3u);
  EXPECT_EQ(result.metrics.stages.size(), 2u);
}

TEST_F(RuntimeTest, FrameRateLeavesOutStartUp) {
  // 20 frames 10 ms apart, the first after 2 s: about 100 frames/s once running.
  // Counting the start-up would give 20 / 2.19 s = 9.1. A loaded machine may stretch the
  // periods (a sleep ends late, never early), hence only > 20.
  const RunResult result = run(R"({
    "nodes": {"src": {"type": "test.counter",
                      "params": {"count": 20, "period_us": 10000, "start_delay_us": 2000000}},
              "out": {"type": "test.record"}},
    "edges": [["src.out", "out.in"]]
  })");
  EXPECT_EQ(result.metrics.frames_completed, 20u);
  EXPECT_GT(result.metrics.frames_per_second, 20.0);
}

TEST_F(RuntimeTest, ConstructorFailureNamesTheNode) {
  try {
    make(R"({
      "nodes": {"src": {"type": "test.counter"},
                "cam": {"type": "test.fail", "params": {"fail_to_start": true}},
                "out": {"type": "test.record"}},
      "edges": [["src.out", "cam.in"], ["cam.out", "out.in"]]
    })");
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(), "node 'cam' (test.fail) failed to start: camera 'xyz' not found");
  }
}

}  // namespace
}  // namespace tilth
