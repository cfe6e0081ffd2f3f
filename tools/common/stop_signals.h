// Stopping a tool on SIGINT / SIGTERM: the first signal asks it to stop (frames in flight
// finish, files are closed), a second exits at once with code 130. The handlers only
// write the signal to a pipe that StopSignalWatcher's thread reads, so whichever thread
// the kernel delivers a signal to (a library's own thread included), it becomes a clean
// stop.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <thread>

namespace tilth::tools {

// Installs the handlers for the whole process; call it first thing in main(). `tool`
// names the message of the second signal. A stop signal that arrives while no watcher
// runs waits for the next one.
void install_stop_handlers(const std::string& tool);

// Calls `stop` on its own thread at the first stop signal, while it lives.
class StopSignalWatcher {
 public:
  // `tool` names the log line.
  StopSignalWatcher(std::string tool, std::function<void()> stop);
  ~StopSignalWatcher();
  StopSignalWatcher(const StopSignalWatcher&) = delete;
  StopSignalWatcher& operator=(const StopSignalWatcher&) = delete;

 private:
  void watch();

  const std::string tool_;
  const std::function<void()> stop_;
  std::thread thread_;
};

// A scratch file, or a folder once its files are gone, that is removed even when a second
// stop signal exits at once, without destructors: the handler unlinks it (unlink(2) and
// rmdir(2) are async-signal-safe). The owner removes it itself on a normal exit and
// ends the registration with this object. At most kScratchPaths at a time.
class ScratchPath {
 public:
  static constexpr int kScratchPaths = 16;

  explicit ScratchPath(const std::filesystem::path& path);  // throws when all are taken
  ~ScratchPath();
  ScratchPath(const ScratchPath&) = delete;
  ScratchPath& operator=(const ScratchPath&) = delete;

 private:
  int slot_;
};

}  // namespace tilth::tools
