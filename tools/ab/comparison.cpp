#include "comparison.h"

#include <algorithm>

namespace tilth::ab {

std::vector<std::string> command_line_of(const std::vector<std::string>& arguments) {
  std::vector<std::string> line{"tilth", "ab"};
  line.insert(line.end(), arguments.begin(), arguments.end());
  return line;
}

Figures Comparison::recording_figures(std::size_t variant, std::size_t recording) const {
  return figures_of({&job(variant, recording).frames});
}

Figures Comparison::variant_figures(std::size_t variant) const {
  std::vector<const std::vector<FrameResult>*> all;
  for (std::size_t r = 0; r < recordings.size(); ++r) all.push_back(&job(variant, r).frames);
  return figures_of(all);
}

std::vector<StageTime> Comparison::variant_stage_times(std::size_t variant) const {
  std::vector<StageTime> times;
  for (std::size_t r = 0; r < recordings.size(); ++r) {
    for (const auto& stage : job(variant, r).stages) {
      auto found = std::find_if(times.begin(), times.end(),
                                [&](const StageTime& known) { return known.node == stage.node; });
      if (found == times.end()) {
        times.push_back({stage.node, stage.type, {}});
        found = times.end() - 1;
      }
      LatencySummary& total = found->latency;
      const std::uint64_t count = total.count + stage.latency.count;
      if (count > 0) {
        total.mean_ms = (total.mean_ms * static_cast<double>(total.count) +
                         stage.latency.mean_ms * static_cast<double>(stage.latency.count)) /
                        static_cast<double>(count);
      }
      total.count = count;
      total.p50_ms = std::max(total.p50_ms, stage.latency.p50_ms);
      total.p99_ms = std::max(total.p99_ms, stage.latency.p99_ms);
      total.max_ms = std::max(total.max_ms, stage.latency.max_ms);
    }
  }
  return times;
}

bool Comparison::any_failed() const {
  return std::any_of(jobs.begin(), jobs.end(), [](const JobResult& job) { return job.failed; });
}

}  // namespace tilth::ab
