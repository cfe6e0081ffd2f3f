// Runs a validated graph as a oneTBB flow graph: makes the stages, admits frames from
// the sources, joins multi-input stages by frame, keeps stateful stages and sinks in
// frame order, times every stage, and stops cleanly. docs/runtime.md explains the
// behaviour a graph author relies on.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "framework/graph_validator.h"
#include "framework/stage_registry.h"
#include "tilth/messages/pipeline_metrics.h"

namespace tilth {

struct RunLimits {
  std::optional<std::uint64_t> max_frames;  // admit at most this many frames
};

// What one node could not store (StageContext::report_data_loss).
struct DataLoss {
  std::string node;
  std::string type;
  std::uint64_t frames = 0;  // frames lost
  std::string first;         // the node's first report: what failed, where
};

struct RunResult {
  PipelineMetrics metrics;
  bool failed = false;   // a source failed, or a stage error stopped the graph (on_error: stop)
  std::string failure;   // the first such failure
  bool stopped = false;  // stop() ended the run
  std::vector<DataLoss> data_lost;  // per node that reported lost data, in graph order
};

class Runtime {
 public:
  // Makes every stage; throws tilth::Error listing each stage that failed to start.
  Runtime(ValidatedGraph graph, const StageRegistry& registry, RunLimits limits = {});
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  // Runs until the end of a stream, the frame limit, stop(), or a stage error with
  // on_error: stop. Frames already in flight finish; then every stage's finish() runs.
  RunResult run();
  // Thread-safe; returns at once.
  void stop();
  // Thread-safe snapshot.
  PipelineMetrics metrics() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tilth
