#include "stop_signals.h"

#include <fcntl.h>
#include <limits.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>

#include "tilth/error.h"
#include "tilth/log.h"

namespace tilth::tools {
namespace {

// Written by the handlers and read by the watcher: a signal's number, or 0 that ends the
// watcher.
int signal_pipe[2] = {-1, -1};
std::once_flag pipe_made;
std::atomic<int> signals_received{0};
static_assert(std::atomic<int>::is_always_lock_free, "used in a signal handler");
char second_signal_message[256];
std::size_t second_signal_length = 0;

// ScratchPath's registrations: a slot is written while its flag is clear, then flagged.
char scratch_paths[ScratchPath::kScratchPaths][PATH_MAX];
std::atomic<bool> scratch_taken[ScratchPath::kScratchPaths];
static_assert(std::atomic<bool>::is_always_lock_free, "used in a signal handler");

// Files first, then the folders they were in.
void remove_scratch_paths() {
  for (int i = 0; i < ScratchPath::kScratchPaths; ++i) {
    if (scratch_taken[i].load()) ::unlink(scratch_paths[i]);
  }
  for (int i = 0; i < ScratchPath::kScratchPaths; ++i) {
    if (scratch_taken[i].load()) ::rmdir(scratch_paths[i]);
  }
}

void make_pipe() {
  std::call_once(pipe_made, [] {
    if (::pipe2(signal_pipe, O_CLOEXEC) != 0 || ::fcntl(signal_pipe[1], F_SETFL, O_NONBLOCK) != 0) {
      throw Error(std::string("cannot create the stop signals' pipe: ") + std::strerror(errno));
    }
  });
}

// Async-signal-safe: atomics, write(2), unlink(2), rmdir(2) and _exit(2) only.
void on_stop_signal(int signal) {
  const int saved_errno = errno;
  if (signals_received.fetch_add(1) > 0) {
    remove_scratch_paths();
    (void)!::write(STDERR_FILENO, second_signal_message, second_signal_length);
    ::_exit(130);
  }
  const auto byte = static_cast<unsigned char>(signal);
  (void)!::write(signal_pipe[1], &byte, 1);
  errno = saved_errno;
}

void wake(unsigned char byte) { (void)!::write(signal_pipe[1], &byte, 1); }

}  // namespace

void install_stop_handlers(const std::string& tool) {
  make_pipe();
  const int length =
      std::snprintf(second_signal_message, sizeof second_signal_message,
                    "%s: %s: second stop signal: exiting at once (code 130)\n",
                    std::string(to_string(LogLevel::kWarning)).c_str(), tool.c_str());
  second_signal_length =
      std::min(static_cast<std::size_t>(std::max(length, 0)), sizeof second_signal_message - 1);
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaddset(&action.sa_mask, SIGINT);
  sigaddset(&action.sa_mask, SIGTERM);
  action.sa_flags = SA_RESTART;
  sigset_t unblock;
  sigemptyset(&unblock);
  for (const int signal : {SIGINT, SIGTERM}) {
    struct sigaction previous {};
    ::sigaction(signal, nullptr, &previous);
    // As a shell leaves it for a background job or nohup: ignored it stays.
    if (previous.sa_handler == SIG_IGN) continue;
    ::sigaction(signal, &action, nullptr);
    sigaddset(&unblock, signal);
  }
  ::pthread_sigmask(SIG_UNBLOCK, &unblock, nullptr);
}

ScratchPath::ScratchPath(const std::filesystem::path& path) : slot_(-1) {
  static std::mutex registering;
  std::lock_guard lock(registering);
  const std::string text = path.string();
  if (text.size() >= PATH_MAX) throw Error(text + ": path too long for a scratch path");
  for (int i = 0; i < kScratchPaths && slot_ < 0; ++i) {
    if (scratch_taken[i].load()) continue;
    std::memcpy(scratch_paths[i], text.c_str(), text.size() + 1);
    scratch_taken[i].store(true);
    slot_ = i;
  }
  if (slot_ < 0)
    throw Error(text + ": more than " + std::to_string(kScratchPaths) + " scratch paths at once");
}

ScratchPath::~ScratchPath() { scratch_taken[slot_].store(false); }

StopSignalWatcher::StopSignalWatcher(std::string tool, std::function<void()> stop)
    : tool_(std::move(tool)), stop_(std::move(stop)) {
  make_pipe();
  thread_ = std::thread([this] { watch(); });
}

StopSignalWatcher::~StopSignalWatcher() {
  wake(0);
  thread_.join();
}

void StopSignalWatcher::watch() {
  unsigned char signal = 0;
  while (true) {
    const ssize_t got = ::read(signal_pipe[0], &signal, 1);
    if (got < 0 && errno == EINTR) continue;
    if (got != 1 || signal == 0) return;
    log(LogLevel::kInfo, tool_,
        std::string(strsignal(signal)) + ": stopping; frames in flight finish");
    stop_();
  }
}

}  // namespace tilth::tools
