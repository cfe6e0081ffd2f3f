// Where a comparison's files go under the output folder:
//   report.html  summary.json  summary.csv  conditions.csv  frames.csv
//   runs/VARIANT/RECORDING/graph.json  frames.jsonl  frames.images/{mask,truth,color}/
//                          job.json (a shard's jobs, job_record.h)
//   shards/I-of-N.json     (a shard's manifest, shard_manifest.h)
#pragma once

#include <filesystem>
#include <string>

#include "job_graph.h"
#include "shard.h"

namespace tilth::ab {

struct OutputLayout {
  std::filesystem::path dir;

  std::filesystem::path report() const { return dir / "report.html"; }
  std::filesystem::path summary_json() const { return dir / "summary.json"; }
  std::filesystem::path summary_csv() const { return dir / "summary.csv"; }
  std::filesystem::path conditions_csv() const { return dir / "conditions.csv"; }
  std::filesystem::path frames_csv() const { return dir / "frames.csv"; }
  std::filesystem::path runs() const { return dir / "runs"; }
  std::filesystem::path shards() const { return dir / "shards"; }
  std::filesystem::path shard_manifest(const Shard& shard) const {
    return shards() /
           (std::to_string(shard.index) + "-of-" + std::to_string(shard.count) + ".json");
  }
  JobFiles job(const std::string& variant, const std::string& recording) const {
    const auto job_dir = runs() / variant / recording;
    return {job_dir / "graph.json", job_dir / "frames.jsonl", job_dir / "frames.images",
            job_dir / "job.json"};
  }
};

// Makes `dir` ready for a new report: it must be missing or empty, or, with
// `overwrite`, hold an earlier report (summary.json), whose files are removed. Throws
// tilth::Error saying which.
void prepare_output(const OutputLayout& layout, bool overwrite);

// Makes `dir` ready for a shard's results beside other shards': it must be missing,
// empty, or hold shard results (runs/, shards/); the shard's earlier manifest is removed
// (its jobs' folders are replaced as they are written). Throws tilth::Error saying which.
void prepare_shard_output(const OutputLayout& layout, const Shard& shard);

}  // namespace tilth::ab
