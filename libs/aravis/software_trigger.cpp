#include "software_trigger.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

#include "aravis/gobject_ptr.h"

namespace tilth::aravis {

std::chrono::nanoseconds grid_period(double rate_hz) {
  return std::chrono::nanoseconds(std::llround(1e9 / rate_hz));
}

std::chrono::steady_clock::time_point next_grid_instant(std::chrono::steady_clock::time_point now,
                                                        std::chrono::nanoseconds period) {
  const auto since_epoch =
      std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch());
  const auto periods = (since_epoch + period - std::chrono::nanoseconds(1)) / period;
  return std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(periods * period));
}

SoftwareTrigger::SoftwareTrigger(ArvCamera* camera, double rate_hz, std::string label, int nice,
                                 Logger log)
    : camera_(camera),
      period_(grid_period(rate_hz)),
      label_(std::move(label)),
      nice_(nice),
      log_(std::move(log)),
      thread_([this] { run(); }) {
  log_.info("software trigger of camera " + label_ + ": every " + std::to_string(period_.count()) +
            " ns of the host's monotonic clock");
}

SoftwareTrigger::~SoftwareTrigger() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void SoftwareTrigger::run() {
  if (nice_ != 0 && setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice_) != 0) {
    log_.warning("cannot give the software trigger's thread nice level " + std::to_string(nice_) +
                 ": " + std::strerror(errno) + " (needs CAP_SYS_NICE)");
  }
  std::string failure;  // of the last trigger; "" when it was sent
  std::uint64_t skipped_in_all = 0;
  bool skipping = false;
  std::unique_lock lock(mutex_);
  auto due = next_grid_instant(std::chrono::steady_clock::now(), period_);
  for (;;) {
    if (wake_.wait_until(lock, due, [this] { return stopping_; })) return;
    lock.unlock();
    const std::string failed = fire();
    if (!failed.empty() && failure.empty()) {
      log_.warning("software trigger of camera " + label_ + " failed: " + failed +
                   " (firing on at every instant)");
    } else if (failed.empty() && !failure.empty()) {
      log_.info("software trigger of camera " + label_ + " answered again");
    }
    failure = failed;
    // Instants that passed while the camera answered are skipped, never fired late.
    const auto next = next_grid_instant(std::chrono::steady_clock::now(), period_);
    const auto skipped = next > due ? (next - due) / period_ - 1 : 0;
    if (skipped > 0) skipped_in_all += static_cast<std::uint64_t>(skipped);
    if (skipped > 0 && !skipping && failure.empty()) {
      log_.warning("software trigger of camera " + label_ + " skipped " +
                   std::to_string(skipped_in_all) +
                   " instant(s) in all, waiting for the camera to answer (the host or the "
                   "network is too slow for the rate)");
    }
    skipping = skipped > 0;
    due = next > due ? next : due + period_;
    lock.lock();
  }
}

std::string SoftwareTrigger::fire() {
  GErrorSlot error;
  arv_camera_software_trigger(camera_, error.out());
  return error.message();
}

}  // namespace tilth::aravis
