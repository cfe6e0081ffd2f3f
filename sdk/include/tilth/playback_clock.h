// Paces a source: waits until a frame's recorded time is due at a playback rate, and
// returns at once when the graph stops. The schedule starts at the first wait after
// construction or restart(); a late frame does not shift it, the frames after it catch up.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>

namespace tilth {

class PlaybackClock {
 public:
  // rate: 1 = as recorded, 2 = twice as fast, 0 = as fast as possible (never waits).
  explicit PlaybackClock(double rate) : rate_(rate) {}

  // The next wait() starts a new schedule (a new pass over a looping recording).
  void restart() {
    std::lock_guard lock(mutex_);
    origin_.reset();
  }

  // Waits until `recorded_ns` (on any clock the source keeps, in ns) is due. False when
  // interrupted.
  bool wait(std::int64_t recorded_ns) {
    std::unique_lock lock(mutex_);
    if (rate_ > 0) {
      if (!origin_) origin_ = Origin{recorded_ns, Clock::now()};
      const double elapsed_ns = static_cast<double>(recorded_ns - origin_->recorded_ns) / rate_;
      const auto due = origin_->started + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double, std::nano>(elapsed_ns));
      wake_.wait_until(lock, due, [this] { return interrupted_; });
    }
    return !interrupted_;
  }

  // From another thread: every wait returns false from now on.
  void interrupt() {
    {
      std::lock_guard lock(mutex_);
      interrupted_ = true;
    }
    wake_.notify_all();
  }

 private:
  using Clock = std::chrono::steady_clock;
  struct Origin {
    std::int64_t recorded_ns;
    Clock::time_point started;
  };

  const double rate_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Origin> origin_;
  bool interrupted_ = false;
};

}  // namespace tilth
