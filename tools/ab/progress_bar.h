// A progress bar for a terminal: redrawn a few times a second on a thread of its own
// from a progress snapshot, and cleared when destroyed.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "job_pool.h"

namespace tilth::ab {

class ProgressBar {
 public:
  explicit ProgressBar(std::function<JobProgress()> progress);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

 private:
  void loop();

  std::function<JobProgress()> progress_;
  const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

// "[########------------]  40%  4/10 graphs  1200 frames  0:07"
std::string progress_text(const JobProgress& progress, double elapsed_s);

}  // namespace tilth::ab
