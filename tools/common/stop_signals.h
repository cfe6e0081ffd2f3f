// Stopping a tool that runs graphs on SIGINT / SIGTERM: the first signal asks it to stop
// (frames in flight finish), a second exits at once.
#pragma once

#include <atomic>
#include <functional>
#include <string>
#include <thread>

namespace tilth::tools {

// Blocks the stop signals in the calling thread. Call it before any thread starts: every
// thread inherits the mask, so only StopSignalWatcher's receives them.
void block_stop_signals();

// Waits for the stop signals on its own thread while it lives.
class StopSignalWatcher {
 public:
  // `tool` names the log lines; `stop` is called on the watcher's thread at the first
  // signal.
  StopSignalWatcher(std::string tool, std::function<void()> stop);
  ~StopSignalWatcher();
  StopSignalWatcher(const StopSignalWatcher&) = delete;
  StopSignalWatcher& operator=(const StopSignalWatcher&) = delete;

 private:
  void watch();

  const std::string tool_;
  const std::function<void()> stop_;
  std::atomic<bool> done_{false};
  std::thread thread_;
};

}  // namespace tilth::tools
