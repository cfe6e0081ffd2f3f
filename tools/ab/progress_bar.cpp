#include "progress_bar.h"

#include <algorithm>
#include <cstdio>

namespace tilth::ab {

ProgressBar::ProgressBar(std::function<JobProgress()> progress) : progress_(std::move(progress)) {
  thread_ = std::thread([this] { loop(); });
}

ProgressBar::~ProgressBar() {
  {
    std::lock_guard lock(mutex_);
    done_ = true;
  }
  wake_.notify_all();
  thread_.join();
  std::fputs("\r\033[K", stdout);
  std::fflush(stdout);
}

void ProgressBar::loop() {
  std::unique_lock lock(mutex_);
  while (!done_) {
    const JobProgress progress = progress_();
    // Nothing to show until the pool has its jobs: soon after it starts.
    if (progress.jobs_total == 0) {
      wake_.wait_for(lock, std::chrono::milliseconds(5));
      continue;
    }
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::fputs(("\r" + progress_text(progress, elapsed) + "\033[K").c_str(), stdout);
    std::fflush(stdout);
    wake_.wait_for(lock, std::chrono::milliseconds(200));
  }
}

std::string progress_text(const JobProgress& progress, double elapsed_s) {
  double fraction = 0.0;
  if (progress.frames_total && *progress.frames_total > 0) {
    fraction =
        static_cast<double>(progress.frames_done) / static_cast<double>(*progress.frames_total);
  } else if (progress.jobs_total > 0) {
    fraction = static_cast<double>(progress.jobs_done) / static_cast<double>(progress.jobs_total);
  }
  fraction = std::clamp(fraction, 0.0, 1.0);
  constexpr int kWidth = 24;
  const int filled = static_cast<int>(fraction * kWidth + 0.5);
  const int seconds = static_cast<int>(elapsed_s);
  char text[160];
  std::snprintf(text, sizeof text, "[%s%s] %3d%%  %zu/%zu graphs  %llu frames  %d:%02d",
                std::string(static_cast<std::size_t>(filled), '#').c_str(),
                std::string(static_cast<std::size_t>(kWidth - filled), '-').c_str(),
                static_cast<int>(fraction * 100.0), progress.jobs_done, progress.jobs_total,
                static_cast<unsigned long long>(progress.frames_done), seconds / 60, seconds % 60);
  return text;
}

}  // namespace tilth::ab
