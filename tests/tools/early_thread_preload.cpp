// Preloaded (LD_PRELOAD) into the tools by test_stopping.py: starts a thread before
// main(), as the static constructors of OpenCV, oneTBB or GLib do, with the signal mask
// and dispositions the process started with. A stop signal the kernel delivers to it
// must stop the tool cleanly like any other.
#include <unistd.h>

#include <thread>

namespace {

struct EarlyThread {
  EarlyThread() {
    std::thread([] {
      while (true) ::pause();
    }).detach();
  }
} early_thread;

}  // namespace
