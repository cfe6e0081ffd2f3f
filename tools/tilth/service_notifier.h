// Tells systemd how a `tilth run` started as a Type=notify service is going: READY=1 once
// the first frame has passed the graph (the cameras stream), WATCHDOG=1 only while frames
// keep completing (a stalled graph is restarted by systemd), a STATUS= line, STOPPING=1
// when asked to stop. Outside systemd (no NOTIFY_SOCKET) it is not started.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

#include "tilth/messages/pipeline_metrics.h"

namespace tilth::cli {

class ServiceNotifier {
 public:
  // True when the process was started by systemd with a notification socket.
  static bool wanted();

  explicit ServiceNotifier(std::function<PipelineMetrics()> metrics);
  ~ServiceNotifier();
  ServiceNotifier(const ServiceNotifier&) = delete;
  ServiceNotifier& operator=(const ServiceNotifier&) = delete;

  // STOPPING=1: the run was asked to stop and is finishing its frames.
  void stopping();

 private:
  void loop();
  void tick();

  std::function<PipelineMetrics()> metrics_;
  // Half the service's WatchdogSec=, or a second without a watchdog.
  std::chrono::microseconds period_;
  std::uint64_t frames_seen_ = 0;
  std::chrono::steady_clock::time_point last_frame_;
  bool ready_ = false;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace tilth::cli
