// Pipeline metrics: per-stage timing and whole-graph throughput, as the runtime
// measures them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "tilth/message.h"

namespace tilth {

struct LatencySummary {
  std::uint64_t count = 0;
  double mean_ms = 0.0;
  double p50_ms = 0.0;
  double p99_ms = 0.0;
  double max_ms = 0.0;
};

struct StageMetrics {
  std::string node;
  std::string type;
  LatencySummary latency;
  std::uint64_t errors = 0;   // process() threw
  std::uint64_t skipped = 0;  // not run because an input was missing
};

struct PipelineMetrics : MessageOf<PipelineMetrics> {
  static constexpr std::string_view kTypeName = "tilth.PipelineMetrics";

  std::vector<StageMetrics> stages;
  std::uint64_t frames_admitted = 0;
  std::uint64_t frames_completed = 0;
  std::uint64_t frames_dropped = 0;  // dropped at admission because the pipeline was full
  std::uint64_t frames_in_flight = 0;
  double frames_per_second = 0.0;  // from the first frame done to the last: no start-up
  LatencySummary end_to_end;       // from capture (host clock) to the last sink

  std::string summary() const override;
};

}  // namespace tilth
