#include "job_pool.h"

#include <algorithm>
#include <thread>

namespace tilth::ab {

JobPool::JobPool(const StageRegistry& registry, std::size_t parallel)
    : registry_(registry), parallel_(std::max<std::size_t>(parallel, 1)) {}

std::vector<JobRun> JobPool::run(std::vector<PreparedJob> jobs) {
  {
    std::lock_guard lock(mutex_);
    progress_ = {};
    progress_.jobs_total = jobs.size();
    std::uint64_t frames = 0;
    bool known = true;
    for (const auto& job : jobs) {
      known = known && job.frames.has_value();
      frames += job.frames.value_or(0);
    }
    if (known) progress_.frames_total = frames;
  }
  std::vector<JobRun> results(jobs.size());
  std::atomic<std::size_t> next{0};
  std::vector<std::thread> workers;
  for (std::size_t w = 0; w < std::min(parallel_, jobs.size()); ++w) {
    workers.emplace_back([&] {
      for (std::size_t i = next++; i < jobs.size() && !stopped_; i = next++) {
        run_one(i, std::move(jobs[i]), results[i]);
      }
    });
  }
  for (auto& worker : workers) worker.join();
  return results;
}

void JobPool::run_one(std::size_t index, PreparedJob job, JobRun& result) {
  std::unique_ptr<Runtime> runtime;
  try {
    runtime = std::make_unique<Runtime>(std::move(job.graph), registry_);
  } catch (const std::exception& error) {
    result.failed = true;
    result.failure = error.what();
    std::lock_guard lock(mutex_);
    ++progress_.jobs_done;
    return;
  }
  {
    std::lock_guard lock(mutex_);
    if (stopped_) return;
    running_[index] = runtime.get();
  }
  RunResult run = runtime->run();
  {
    std::lock_guard lock(mutex_);
    running_.erase(index);
    ++progress_.jobs_done;
    progress_.frames_done += run.metrics.frames_completed;
  }
  runtime.reset();  // the sinks close their files
  // A graph whose sinks lost data has no complete results to compare.
  result.failed = run.failed || !run.data_lost.empty();
  if (run.failed) {
    result.failure = run.failure;
  } else if (!run.data_lost.empty()) {
    const DataLoss& loss = run.data_lost.front();
    result.failure = "node '" + loss.node + "' (" + loss.type + ") lost data: " + loss.first;
  }
  result.metrics = std::move(run.metrics);
}

void JobPool::stop() {
  std::lock_guard lock(mutex_);
  stopped_ = true;
  for (auto& [index, runtime] : running_) runtime->stop();
}

JobProgress JobPool::progress() const {
  std::lock_guard lock(mutex_);
  JobProgress now = progress_;
  for (const auto& [index, runtime] : running_)
    now.frames_done += runtime->metrics().frames_completed;
  return now;
}

}  // namespace tilth::ab
