// Runs the graphs of a comparison, a bounded number at once, each as fast as it goes.
// stop() ends them all cleanly (frames in flight finish, sinks flush) and starts no more.
#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "framework/graph_validator.h"
#include "framework/runtime.h"
#include "framework/stage_registry.h"

namespace tilth::ab {

struct PreparedJob {
  ValidatedGraph graph;
  std::optional<std::size_t> frames;  // expected, when known
};

struct JobRun {
  bool failed = false;
  std::string failure;  // a stage failed to start, or the run failed
  PipelineMetrics metrics;
};

struct JobProgress {
  std::size_t jobs_done = 0;
  std::size_t jobs_total = 0;
  std::uint64_t frames_done = 0;
  std::optional<std::uint64_t> frames_total;  // when every job's is known
};

class JobPool {
 public:
  JobPool(const StageRegistry& registry, std::size_t parallel);

  // Runs every job; returns their runs in the jobs' order.
  std::vector<JobRun> run(std::vector<PreparedJob> jobs);
  void stop();  // thread-safe
  bool stopped() const { return stopped_; }
  JobProgress progress() const;  // thread-safe

 private:
  void run_one(std::size_t index, PreparedJob job, JobRun& result);

  const StageRegistry& registry_;
  const std::size_t parallel_;
  std::atomic<bool> stopped_{false};
  mutable std::mutex mutex_;
  std::map<std::size_t, Runtime*> running_;
  JobProgress progress_;
};

}  // namespace tilth::ab
