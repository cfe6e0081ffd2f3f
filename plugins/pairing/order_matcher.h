// Pairs the frames of two cameras fired by one trigger, by trigger order. Block ids of
// both cameras advance by one per trigger, so once a first pair (found by capture time)
// fixes the difference between the cameras' ids, depth id i pairs with colour id
// i + difference. A frame whose partner id the other camera has passed (lost there), or
// that waited longer than max_wait, is dropped. A pair whose capture times differ by more than the
// tolerance means the order slipped (a restarted camera, a missed trigger): the difference is found
// again.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "frame_matcher.h"

namespace tilth::pairing {

class OrderMatcher final : public FrameMatcher {
 public:
  OrderMatcher(std::int64_t tolerance_ns, std::int64_t max_wait_ns)
      : tolerance_ns_(tolerance_ns), max_wait_ns_(max_wait_ns) {}

  std::vector<MatchedPair> add(Side side, PendingFrame frame) override;
  // Also forgets the id difference.
  void clear() override;
  std::uint64_t unmatched(Side side) const override { return unmatched_[side]; }

 private:
  bool find_id_difference();
  void drop_front(Side side);
  std::int64_t id(Side side) const;

  const std::int64_t tolerance_ns_;
  const std::int64_t max_wait_ns_;
  std::int64_t newest_ns_ = 0;
  std::optional<std::int64_t> id_difference_;  // colour block id - depth block id
  std::array<std::deque<PendingFrame>, 2> waiting_;
  std::array<std::optional<std::uint64_t>, 2> last_id_;
  std::array<std::uint64_t, 2> unmatched_{0, 0};
};

}  // namespace tilth::pairing
