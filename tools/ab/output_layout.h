// Where a comparison's files go under the output folder:
//   report.html  summary.json  summary.csv  frames.csv
//   runs/VARIANT/RECORDING/graph.json  frames.jsonl  frames.images/{mask,truth,color}/
#pragma once

#include <filesystem>
#include <string>

#include "job_graph.h"

namespace tilth::ab {

struct OutputLayout {
  std::filesystem::path dir;

  std::filesystem::path report() const { return dir / "report.html"; }
  std::filesystem::path summary_json() const { return dir / "summary.json"; }
  std::filesystem::path summary_csv() const { return dir / "summary.csv"; }
  std::filesystem::path frames_csv() const { return dir / "frames.csv"; }
  std::filesystem::path runs() const { return dir / "runs"; }
  JobFiles job(const std::string& variant, const std::string& recording) const {
    const auto job_dir = runs() / variant / recording;
    return {job_dir / "graph.json", job_dir / "frames.jsonl", job_dir / "frames.images"};
  }
};

// Makes `dir` ready for a new report: it must be missing or empty, or, with
// `overwrite`, hold an earlier report (summary.json), whose files are removed. Throws
// tilth::Error saying which.
void prepare_output(const OutputLayout& layout, bool overwrite);

}  // namespace tilth::ab
