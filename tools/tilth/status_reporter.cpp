#include "status_reporter.h"

#include <cstdio>
#include <iomanip>
#include <sstream>

#include "tilth/log.h"

namespace tilth::cli {
namespace {

std::uint64_t total_skipped(const PipelineMetrics& metrics) {
  std::uint64_t skipped = 0;
  for (const auto& stage : metrics.stages) skipped += stage.skipped + stage.errors;
  return skipped;
}

}  // namespace

std::string status_text(const PipelineMetrics& metrics) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(1) << "frames " << metrics.frames_completed << "  fps "
      << metrics.frames_per_second << "  dropped " << metrics.frames_dropped << "  skipped "
      << total_skipped(metrics) << "  in flight " << metrics.frames_in_flight << "  latency p50 "
      << metrics.end_to_end.p50_ms << " ms";
  return out.str();
}

std::string metrics_report(const PipelineMetrics& metrics) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3);
  out << std::left << std::setw(24) << "node" << std::setw(26) << "type" << std::right
      << std::setw(8) << "frames" << std::setw(11) << "mean ms" << std::setw(11) << "p50 ms"
      << std::setw(11) << "p99 ms" << std::setw(8) << "errors" << std::setw(9) << "skipped"
      << "\n";
  for (const auto& stage : metrics.stages) {
    out << std::left << std::setw(24) << stage.node << std::setw(26) << stage.type << std::right
        << std::setw(8) << stage.latency.count << std::setw(11) << stage.latency.mean_ms
        << std::setw(11) << stage.latency.p50_ms << std::setw(11) << stage.latency.p99_ms
        << std::setw(8) << stage.errors << std::setw(9) << stage.skipped << "\n";
  }
  out << std::setprecision(1) << metrics.frames_completed << " frames completed, "
      << metrics.frames_dropped << " dropped, " << metrics.frames_per_second
      << " frames/s; capture-to-sink latency mean " << std::setprecision(3)
      << metrics.end_to_end.mean_ms << " ms, p50 " << metrics.end_to_end.p50_ms << " ms, p99 "
      << metrics.end_to_end.p99_ms << " ms\n";
  return out.str();
}

StatusReporter::StatusReporter(std::function<PipelineMetrics()> metrics, bool terminal)
    : metrics_(std::move(metrics)), terminal_(terminal) {
  if (terminal_) {
    set_log_handler([this](LogLevel level, std::string_view where, std::string_view message) {
      // Called with the log lock held; the status line is redrawn on the next tick.
      std::lock_guard lock(mutex_);
      clear_locked();
      std::fprintf(stderr, "%.*s: %.*s: %.*s\n", static_cast<int>(to_string(level).size()),
                   to_string(level).data(), static_cast<int>(where.size()), where.data(),
                   static_cast<int>(message.size()), message.data());
    });
  }
  thread_ = std::thread([this] { loop(); });
}

StatusReporter::~StatusReporter() {
  {
    std::lock_guard lock(mutex_);
    done_ = true;
    wake_.notify_all();
  }
  thread_.join();
  if (terminal_) set_log_handler({});
  std::lock_guard lock(mutex_);
  clear_locked();
}

void StatusReporter::loop() {
  const auto period = terminal_ ? std::chrono::milliseconds(250) : std::chrono::seconds(10);
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, period, [this] { return done_; })) {
    lock.unlock();
    const PipelineMetrics metrics = metrics_();
    lock.lock();
    if (done_) break;
    if (terminal_) {
      draw_locked(metrics);
    } else {
      lock.unlock();
      log(LogLevel::kInfo, "status", status_text(metrics));
      lock.lock();
    }
  }
}

void StatusReporter::draw_locked(const PipelineMetrics& metrics) {
  std::fprintf(stderr, "\r\033[K%s", status_text(metrics).c_str());
  std::fflush(stderr);
  line_shown_ = true;
}

void StatusReporter::clear_locked() {
  if (!line_shown_) return;
  std::fprintf(stderr, "\r\033[K");
  line_shown_ = false;
}

}  // namespace tilth::cli
