#include "service_notifier.h"

#include <cstdlib>
#include <string>

#include <systemd/sd-daemon.h>

#include "status_reporter.h"
#include "tilth/log.h"

namespace tilth::cli {
namespace {

constexpr std::chrono::microseconds kPeriodWithoutWatchdog = std::chrono::seconds(1);
// Until the first frame, readiness is checked this often.
constexpr std::chrono::microseconds kReadyPoll = std::chrono::milliseconds(100);

void notify(const std::string& state) {
  const int sent = sd_notify(0, state.c_str());
  if (sent < 0) {
    log(LogLevel::kWarning, "service",
        "cannot notify systemd (" + state.substr(0, state.find('\n')) + "): error " +
            std::to_string(-sent));
  }
}

}  // namespace

bool ServiceNotifier::wanted() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  return socket != nullptr && *socket != '\0';
}

ServiceNotifier::ServiceNotifier(std::function<PipelineMetrics()> metrics)
    : metrics_(std::move(metrics)), period_(kPeriodWithoutWatchdog) {
  std::uint64_t watchdog_us = 0;
  if (sd_watchdog_enabled(0, &watchdog_us) > 0 && watchdog_us > 0) {
    period_ = std::chrono::microseconds(watchdog_us / 2);
  }
  last_frame_ = std::chrono::steady_clock::now();
  notify("STATUS=waiting for the first frame");
  thread_ = std::thread([this] { loop(); });
}

ServiceNotifier::~ServiceNotifier() {
  {
    std::lock_guard lock(mutex_);
    done_ = true;
    wake_.notify_all();
  }
  thread_.join();
}

void ServiceNotifier::stopping() {
  notify("STOPPING=1\nSTATUS=stopping: finishing the frames in flight");
}

void ServiceNotifier::loop() {
  std::unique_lock lock(mutex_);
  while (!wake_.wait_for(lock, ready_ ? period_ : std::min(period_, kReadyPoll),
                         [this] { return done_; })) {
    lock.unlock();
    tick();
    lock.lock();
  }
}

void ServiceNotifier::tick() {
  const PipelineMetrics metrics = metrics_();
  const auto now = std::chrono::steady_clock::now();
  if (metrics.frames_completed > frames_seen_) {
    frames_seen_ = metrics.frames_completed;
    last_frame_ = now;
    notify(std::string(ready_ ? "WATCHDOG=1" : "READY=1") + "\nSTATUS=" + status_text(metrics));
    ready_ = true;
    return;
  }
  if (!ready_) return;
  const auto silent_s = std::chrono::duration_cast<std::chrono::seconds>(now - last_frame_);
  notify("STATUS=no frame completed for " + std::to_string(silent_s.count()) + " s; " +
         status_text(metrics));
}

}  // namespace tilth::cli
