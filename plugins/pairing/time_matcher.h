// Pairs the frames of two free-running cameras by capture time. Each camera's frames
// arrive in capture order; the oldest waiting frame is paired with the other camera's
// oldest frame when their capture times differ by at most the tolerance and no waiting
// frame is closer to it, and is dropped as unmatched when no frame can still match it
// (the other camera is already past it, or it waited longer than max_wait). A pair is
// decided as soon as both frames are in, so pairing adds no frame of latency; with a
// tolerance below half the frame period at most one frame can match, so greed is exact.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

#include "frame_matcher.h"

namespace tilth::pairing {

class TimeMatcher final : public FrameMatcher {
 public:
  TimeMatcher(std::int64_t tolerance_ns, std::int64_t max_wait_ns)
      : tolerance_ns_(tolerance_ns), max_wait_ns_(max_wait_ns) {}

  std::vector<MatchedPair> add(Side side, PendingFrame frame) override;
  void clear() override;
  std::uint64_t unmatched(Side side) const override { return unmatched_[side]; }

 private:
  void drop_front(Side side);

  const std::int64_t tolerance_ns_;
  const std::int64_t max_wait_ns_;
  std::array<std::deque<PendingFrame>, 2> waiting_;
  std::array<std::uint64_t, 2> unmatched_{0, 0};
  std::int64_t newest_ns_ = 0;
};

}  // namespace tilth::pairing
