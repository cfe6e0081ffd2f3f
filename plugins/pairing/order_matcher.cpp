#include "order_matcher.h"

#include <algorithm>
#include <cstdlib>

namespace tilth::pairing {

std::vector<MatchedPair> OrderMatcher::add(Side side, PendingFrame frame) {
  auto& mine = waiting_[side];
  if (last_id_[side] && frame.info.frame_id <= *last_id_[side]) {
    // Block ids went backwards: the camera restarted.
    unmatched_[side] += mine.size();
    mine.clear();
    id_difference_.reset();
  }
  last_id_[side] = frame.info.frame_id;
  newest_ns_ = std::max(newest_ns_, frame.capture_ns);
  mine.push_back(std::move(frame));

  std::vector<MatchedPair> pairs;
  while (!waiting_[kDepth].empty() && !waiting_[kColor].empty()) {
    if (!id_difference_ && !find_id_difference()) continue;
    const std::int64_t depth_id = id(kDepth);
    const std::int64_t color_id = id(kColor) - *id_difference_;
    if (depth_id < color_id) {
      drop_front(kDepth);
    } else if (color_id < depth_id) {
      drop_front(kColor);
    } else if (std::llabs(waiting_[kDepth].front().capture_ns -
                          waiting_[kColor].front().capture_ns) > tolerance_ns_) {
      id_difference_.reset();
    } else {
      pairs.push_back({std::move(waiting_[kDepth].front()), std::move(waiting_[kColor].front())});
      waiting_[kDepth].pop_front();
      waiting_[kColor].pop_front();
    }
  }
  for (Side s : {kDepth, kColor}) {
    while (!waiting_[s].empty() && newest_ns_ - waiting_[s].front().capture_ns > max_wait_ns_) {
      drop_front(s);
    }
  }
  return pairs;
}

// From the two oldest frames: equal capture times (within the tolerance) fix the id
// difference; otherwise the older one has no partner and is dropped (false).
bool OrderMatcher::find_id_difference() {
  const auto& depth = waiting_[kDepth].front();
  const auto& color = waiting_[kColor].front();
  const std::int64_t gap = color.capture_ns - depth.capture_ns;
  if (std::llabs(gap) <= tolerance_ns_) {
    id_difference_ = static_cast<std::int64_t>(color.info.frame_id) -
                     static_cast<std::int64_t>(depth.info.frame_id);
    return true;
  }
  drop_front(gap > 0 ? kDepth : kColor);
  return false;
}

void OrderMatcher::clear() {
  for (Side side : {kDepth, kColor}) {
    unmatched_[side] += waiting_[side].size();
    waiting_[side].clear();
  }
  id_difference_.reset();
}

void OrderMatcher::drop_front(Side side) {
  waiting_[side].pop_front();
  ++unmatched_[side];
}

std::int64_t OrderMatcher::id(Side side) const {
  return static_cast<std::int64_t>(waiting_[side].front().info.frame_id);
}

}  // namespace tilth::pairing
