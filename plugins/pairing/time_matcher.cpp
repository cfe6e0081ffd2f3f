#include "time_matcher.h"

#include <algorithm>
#include <cstdlib>

namespace tilth::pairing {

std::vector<MatchedPair> TimeMatcher::add(Side side, PendingFrame frame) {
  auto& mine = waiting_[side];
  // A capture time going backwards means the camera's clock restarted: what waits from
  // it is of another timeline.
  while (!mine.empty() && mine.back().capture_ns >= frame.capture_ns) {
    mine.pop_back();
    ++unmatched_[side];
  }
  newest_ns_ = std::max(newest_ns_, frame.capture_ns);
  mine.push_back(std::move(frame));

  std::vector<MatchedPair> pairs;
  for (;;) {
    const bool depth_waits = !waiting_[kDepth].empty();
    const bool color_waits = !waiting_[kColor].empty();
    if (!depth_waits && !color_waits) break;
    if (depth_waits != color_waits) {
      const Side alone = depth_waits ? kDepth : kColor;
      if (newest_ns_ - waiting_[alone].front().capture_ns <= max_wait_ns_) break;
      drop_front(alone);
      continue;
    }
    const Side older = waiting_[kDepth].front().capture_ns <= waiting_[kColor].front().capture_ns
                           ? kDepth
                           : kColor;
    const Side newer = older == kDepth ? kColor : kDepth;
    const std::int64_t partner_ns = waiting_[newer].front().capture_ns;
    const std::int64_t gap = partner_ns - waiting_[older].front().capture_ns;
    // Every frame of the newer camera, now and to come, is at least this far away.
    if (gap > tolerance_ns_) {
      drop_front(older);
      continue;
    }
    // The older camera's next frame may be the partner's closer match.
    if (waiting_[older].size() > 1 &&
        std::llabs(waiting_[older][1].capture_ns - partner_ns) < gap) {
      drop_front(older);
      continue;
    }
    MatchedPair pair{std::move(waiting_[kDepth].front()), std::move(waiting_[kColor].front())};
    waiting_[kDepth].pop_front();
    waiting_[kColor].pop_front();
    pairs.push_back(std::move(pair));
  }
  return pairs;
}

void TimeMatcher::clear() {
  for (Side side : {kDepth, kColor}) {
    unmatched_[side] += waiting_[side].size();
    waiting_[side].clear();
  }
}

void TimeMatcher::drop_front(Side side) {
  waiting_[side].pop_front();
  ++unmatched_[side];
}

}  // namespace tilth::pairing
