// install_stop_handlers and StopSignalWatcher, with each signal sent to a thread that
// was started before the handlers were installed, as the static constructors of OpenCV,
// oneTBB or GLib start threads before main(): whichever thread the kernel delivers a
// stop signal to, the first one stops, a second exits at once with code 130. Each case
// runs in a child process of its own (a death test), as signals are process-wide.
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <future>
#include <thread>

#include <gtest/gtest.h>

#include "stop_signals.h"

namespace tilth::tools {
namespace {

using namespace std::chrono_literals;

// A thread with the signal mask and dispositions the process started with.
class LibraryThread {
 public:
  LibraryThread() {
    std::promise<pid_t> started;
    thread_ = std::thread([this, &started] {
      started.set_value(static_cast<pid_t>(::syscall(SYS_gettid)));
      while (!done_) std::this_thread::sleep_for(1ms);
    });
    tid_ = started.get_future().get();
  }
  ~LibraryThread() {
    done_ = true;
    thread_.join();
  }
  // Delivers `signal` to this thread alone.
  void signal(int signal) const { ::syscall(SYS_tgkill, ::getpid(), tid_, signal); }

 private:
  std::atomic<bool> done_{false};
  std::thread thread_;
  pid_t tid_ = 0;
};

// Exits 0 when the watcher's stop callback ran within 5 s of `send`, else 1.
template <class Send>
void exit_when_stopped(Send send) {
  std::promise<void> stopped;
  const StopSignalWatcher watcher("test", [&stopped] { stopped.set_value(); });
  send();
  const bool in_time = stopped.get_future().wait_for(5s) == std::future_status::ready;
  std::_Exit(in_time ? 0 : 1);
}

class StopSignalsTest : public testing::Test {
 protected:
  void SetUp() override { GTEST_FLAG_SET(death_test_style, "threadsafe"); }
};

TEST_F(StopSignalsTest, SigtermToALibraryThreadStopsCleanly) {
  EXPECT_EXIT(
      {
        const LibraryThread library;
        install_stop_handlers("test");
        exit_when_stopped([&] { library.signal(SIGTERM); });
      },
      testing::ExitedWithCode(0), "info: test: Terminated: stopping; frames in flight finish");
}

TEST_F(StopSignalsTest, SigintToALibraryThreadStopsCleanly) {
  EXPECT_EXIT(
      {
        const LibraryThread library;
        install_stop_handlers("test");
        exit_when_stopped([&] { library.signal(SIGINT); });
      },
      testing::ExitedWithCode(0), "info: test: Interrupt: stopping; frames in flight finish");
}

TEST_F(StopSignalsTest, ASignalBeforeTheWatcherStartsStopsWhenItDoes) {
  EXPECT_EXIT(
      {
        install_stop_handlers("test");
        std::raise(SIGTERM);
        exit_when_stopped([] {});
      },
      testing::ExitedWithCode(0), "Terminated: stopping");
}

TEST_F(StopSignalsTest, ASecondSignalExitsAtOnceWith130) {
  EXPECT_EXIT(
      {
        const LibraryThread library;
        install_stop_handlers("test");
        // The first stop never completes: only the second signal can end the process.
        const StopSignalWatcher watcher("test", [] {});
        library.signal(SIGTERM);
        std::this_thread::sleep_for(200ms);
        library.signal(SIGINT);
        std::this_thread::sleep_for(5s);
        std::_Exit(0);
      },
      testing::ExitedWithCode(130),
      "warning: test: second stop signal: exiting at once \\(code 130\\)");
}

TEST_F(StopSignalsTest, AnIgnoredSignalStaysIgnored) {
  EXPECT_EXIT(
      {
        std::signal(SIGINT, SIG_IGN);
        install_stop_handlers("test");
        std::promise<void> stopped;
        const StopSignalWatcher watcher("test", [&stopped] { stopped.set_value(); });
        std::raise(SIGINT);
        std::_Exit(stopped.get_future().wait_for(500ms) == std::future_status::timeout ? 0 : 1);
      },
      testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace tilth::tools
