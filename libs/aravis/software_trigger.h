// Fires a camera's software trigger (TriggerSoftware) at a fixed rate, at the instants
// of a grid on the host's monotonic clock: every multiple of the period since the
// clock's epoch. Every camera of the host triggered at one rate is fired at the same
// instants with no state shared between them, so the cameras of a rig expose together
// (docs/pairing.md). Each camera is fired from a thread of its own, so one that is slow
// to answer delays neither the frames nor the other camera.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include <arv.h>

#include "tilth/log.h"

namespace tilth::aravis {

// The first grid instant at or after `now` for a period of `period`.
std::chrono::steady_clock::time_point next_grid_instant(std::chrono::steady_clock::time_point now,
                                                        std::chrono::nanoseconds period);

// The grid's period for `rate_hz` (> 0), in whole nanoseconds: the same for every camera
// at that rate.
std::chrono::nanoseconds grid_period(double rate_hz);

class SoftwareTrigger {
 public:
  // Starts firing `camera` (already acquiring, in TriggerSource Software); the camera
  // must outlive this object. `nice`: the firing thread's nice level (0 = the process's).
  SoftwareTrigger(ArvCamera* camera, double rate_hz, std::string label, int nice, Logger log);
  ~SoftwareTrigger();
  SoftwareTrigger(const SoftwareTrigger&) = delete;
  SoftwareTrigger& operator=(const SoftwareTrigger&) = delete;

 private:
  void run();
  // Aravis's message when the camera refused or did not answer; "" when it was sent.
  std::string fire();

  ArvCamera* const camera_;
  const std::chrono::nanoseconds period_;
  const std::string label_;
  const int nice_;
  const Logger log_;

  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;  // last: started when everything it uses exists
};

}  // namespace tilth::aravis
