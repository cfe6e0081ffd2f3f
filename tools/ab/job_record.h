// What a job of a sharded comparison leaves beside its frames (runs/VARIANT/RECORDING/
// job.json): whether it failed and why, and the chain's stage times, so that `tilth ab
// merge` rebuilds the job's result without running it again.
#pragma once

#include "comparison.h"
#include "job_graph.h"

namespace tilth::ab {

// Writes `result`'s outcome and stage times to files.record.
void write_job_record(const JobFiles& files, const JobResult& result);

// The job's result from files.record and its frames (files.frames), judged with
// `no_soil_below`, its images at files.images (read_job_frames). Throws tilth::Error naming a file
// that is missing or malformed.
JobResult read_job_record(const JobFiles& files, double no_soil_below);

// The job's frames (files.frames, when the sink wrote them), judged with
// `no_soil_below`, and its images (files.images, when saved), into `result`.
void read_job_frames(const JobFiles& files, double no_soil_below, JobResult& result);

}  // namespace tilth::ab
