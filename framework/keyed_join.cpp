#include "framework/keyed_join.h"

namespace tilth {

std::optional<std::vector<BundlePtr>> KeyedJoin::add(std::uint64_t sequence, std::size_t slot,
                                                     BundlePtr bundle) {
  if (slots_ == 1) return std::vector<BundlePtr>{std::move(bundle)};
  std::lock_guard lock(mutex_);
  auto [it, inserted] =
      pending_.try_emplace(sequence, Pending{std::vector<BundlePtr>(slots_), slots_});
  it->second.bundles[slot] = std::move(bundle);
  if (--it->second.missing > 0) return std::nullopt;
  std::vector<BundlePtr> complete = std::move(it->second.bundles);
  pending_.erase(it);
  return complete;
}

std::size_t KeyedJoin::pending() const {
  std::lock_guard lock(mutex_);
  return pending_.size();
}

}  // namespace tilth
