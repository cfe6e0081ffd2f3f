// The results of a comparison: for every (variant, recording) job its judged frames and
// the chain's stage times, and the figures derived from them.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "figures.h"
#include "recording_list.h"
#include "tilth/messages/pipeline_metrics.h"
#include "variant.h"

namespace tilth::ab {

struct StageTime {
  std::string node;  // as named in the chain file
  std::string type;
  LatencySummary latency;
};

struct JobResult {
  bool failed = false;
  std::string failure;
  std::vector<FrameResult> frames;
  std::vector<StageTime> stages;  // the chain's stages, in graph order
  double frames_per_second = 0.0;
  std::filesystem::path images;  // the images its evaluation sink saved, if it saved them
};

// How a report was made, stamped on it so that its figures can be traced to a run.
struct ReportStamp {
  std::vector<std::string> command_line;  // of the run, or of the merge
  std::filesystem::path working_directory;
  std::vector<std::vector<std::string>> shard_command_lines;  // a merge's shards'
};

// "tilth", "ab", then the arguments of `tilth ab` as given.
std::vector<std::string> command_line_of(const std::vector<std::string>& arguments);

struct Comparison {
  std::vector<Variant> variants;
  std::vector<Recording> recordings;
  std::vector<JobResult> jobs;  // variant-major: jobs[v * recordings.size() + r]
  double no_soil_below = 0.01;
  std::size_t baseline = 0;  // the variant the others are paired with
  ReportStamp stamp;

  const JobResult& job(std::size_t variant, std::size_t recording) const {
    return jobs[variant * recordings.size() + recording];
  }
  Figures recording_figures(std::size_t variant, std::size_t recording) const;
  Figures variant_figures(std::size_t variant) const;  // every recording pooled
  // Per stage over every recording: count-weighted mean, the largest p50, p99 and max.
  std::vector<StageTime> variant_stage_times(std::size_t variant) const;
  bool any_failed() const;
};

}  // namespace tilth::ab
