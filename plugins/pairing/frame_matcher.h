// Decides which depth frame goes with which colour frame: by capture time for
// free-running cameras (TimeMatcher), by trigger order for triggered ones (OrderMatcher).
// Frames that find no partner are counted and dropped, never paired wrongly.
#pragma once

#include <cstdint>
#include <vector>

#include "pending_frame.h"

namespace tilth::pairing {

class FrameMatcher {
 public:
  virtual ~FrameMatcher() = default;
  // Adds one camera's next frame (each camera's arrive in order); returns the pairs this
  // decides, oldest first.
  virtual std::vector<MatchedPair> add(Side side, PendingFrame frame) = 0;
  // Drops every waiting frame as unmatched (a camera was lost).
  virtual void clear() = 0;
  virtual std::uint64_t unmatched(Side side) const = 0;
};

}  // namespace tilth::pairing
