#include "stop_signals.h"

#include <csignal>
#include <cstdlib>
#include <cstring>
#include <ctime>

#include "tilth/log.h"

namespace tilth::tools {
namespace {

sigset_t stop_signals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  return set;
}

}  // namespace

void block_stop_signals() {
  const sigset_t set = stop_signals();
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

StopSignalWatcher::StopSignalWatcher(std::string tool, std::function<void()> stop)
    : tool_(std::move(tool)), stop_(std::move(stop)), thread_([this] { watch(); }) {}

StopSignalWatcher::~StopSignalWatcher() {
  done_ = true;
  thread_.join();
}

void StopSignalWatcher::watch() {
  const sigset_t set = stop_signals();
  const timespec tick{0, 100'000'000};
  int received = 0;
  while (!done_) {
    const int signal = sigtimedwait(&set, nullptr, &tick);
    if (signal <= 0) continue;
    if (++received > 1) {
      log(LogLevel::kWarning, tool_, "second stop signal: exiting without finishing frames");
      std::_Exit(130);
    }
    log(LogLevel::kInfo, tool_,
        std::string(strsignal(signal)) + ": stopping; frames in flight finish");
    stop_();
  }
}

}  // namespace tilth::tools
