// Tells the log when frames start or stop showing one material only (an automatic
// segmentation then falls back on its absolute rule), once per change, not per frame.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

#include "tilth/log.h"

namespace tilth::segmentation {

class OneMaterialNotice {
 public:
  explicit OneMaterialNotice(Logger log) : log_(std::move(log)) {}

  // `why`: the measure and its limit, e.g. "class gap 0.012 < 0.05".
  void report(std::uint64_t frame_id, bool one_material, const std::string& why) {
    const int now = one_material ? 1 : 0;
    if (state_.exchange(now) == now) return;
    log_.info("frame " + std::to_string(frame_id) +
              (one_material ? ": one material only (" + why + "); the absolute rule decides"
                            : ": two materials again (" + why + ")"));
  }

 private:
  Logger log_;
  std::atomic<int> state_{0};
};

}  // namespace tilth::segmentation
