// Stage types for the framework tests, registered in-process (StageRegistry::add):
// a counting source, a parallel transform with a settable delay, a two-input adder, a
// synchronizer pairing equal counts, a stage that throws on chosen frames, a sink that
// records what it receives, and one that asks for the pipeline's metrics while the
// runtime is still making its stages.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <vector>

#include "framework/stage_registry.h"
#include "tilth/message.h"
#include "tilth/packet.h"

namespace tilth::testing {

// A plugin-defined message type, as any plugin may add.
struct Count : MessageOf<Count> {
  static constexpr std::string_view kTypeName = "test.Count";
  std::int64_t value = 0;
  explicit Count(std::int64_t v) : value(v) {}
};

struct Received {
  FrameInfo info;
  std::int64_t value = 0;
  bool skipped = false;
};

// What the recording sinks saw, per node; shared by the tests of one process.
struct SinkLog {
  std::mutex mutex;
  std::vector<Received> frames;
  std::atomic<int> concurrent{0};
  std::atomic<int> max_concurrent{0};
  bool finished = false;
  std::size_t stages_in_metrics_at_start = 0;  // test.metrics_probe: what its constructor saw
};

SinkLog& sink_log(const std::string& node);
void reset_sink_logs();

// The most frames that were inside test.delay at once.
int max_parallel_delays();

void register_test_stages(StageRegistry& registry);

}  // namespace tilth::testing
