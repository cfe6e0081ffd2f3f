// Reports a running graph's progress: a live status line (frames, fps, drops) on a
// terminal, a plain log line every 10 s otherwise. Log lines never interleave with the
// status line.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

#include "tilth/messages/pipeline_metrics.h"

namespace tilth::cli {

class StatusReporter {
 public:
  StatusReporter(std::function<PipelineMetrics()> metrics, bool terminal);
  ~StatusReporter();  // stops the reporter and clears the status line

 private:
  void loop();
  void draw_locked(const PipelineMetrics& metrics);
  void clear_locked();

  std::function<PipelineMetrics()> metrics_;
  const bool terminal_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  bool line_shown_ = false;
  std::thread thread_;
};

// One line: "frames 120  fps 29.8  dropped 0  skipped 0  in flight 2  latency p50 4.1 ms".
std::string status_text(const PipelineMetrics& metrics);
// The end-of-run table: per-stage latency and the whole graph's figures.
std::string metrics_report(const PipelineMetrics& metrics);

}  // namespace tilth::cli
