#include "job_record.h"

#include "frame_records.h"
#include "report_numbers.h"
#include "tilth/json_input.h"

namespace tilth::ab {

namespace fs = std::filesystem;
using nlohmann::json;

void write_job_record(const JobFiles& files, const JobResult& result) {
  const nlohmann::ordered_json record = {{"failed", result.failed},
                                         {"failure", result.failure},
                                         {"frames_per_second", result.frames_per_second},
                                         {"stages", stage_times_json(result.stages)}};
  write_text(files.record, record.dump(2) + "\n");
}

JobResult read_job_record(const JobFiles& files, double no_soil_below) {
  const std::string origin = files.record.string();
  const json record = parse_json(read_json_text(files.record, "job record"), origin);
  JobResult result;
  try {
    result.failed = record.at("failed").get<bool>();
    result.failure = record.at("failure").get<std::string>();
    result.frames_per_second = record.at("frames_per_second").get<double>();
    for (const json& stage : record.at("stages")) {
      result.stages.push_back(
          {stage.at("node").get<std::string>(),
           stage.at("type").get<std::string>(),
           {stage.at("frames").get<std::uint64_t>(), stage.at("mean_ms").get<double>(),
            stage.at("p50_ms").get<double>(), stage.at("p99_ms").get<double>(),
            stage.at("max_ms").get<double>()}});
    }
  } catch (const json::exception& error) {
    throw Error(origin + ": not a job record of tilth ab: " + error.what());
  }
  read_job_frames(files, no_soil_below, result);
  return result;
}

void read_job_frames(const JobFiles& files, double no_soil_below, JobResult& result) {
  if (fs::exists(files.frames)) {
    result.frames = judge_frames(read_frame_records(files.frames), no_soil_below);
  }
  if (fs::exists(files.images)) result.images = files.images;
}

}  // namespace tilth::ab
