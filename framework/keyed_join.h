// Joins the bundles of a node's predecessors by sequence number.
//
//   pred A seq 7 --+
//                  +--> [seq 7: A, B] --> complete set for seq 7
//   pred B seq 7 --+
//
// Invariant: each predecessor delivers each sequence number exactly once, so a set is
// complete when its last missing slot arrives. Thread-safe.
#pragma once

#include <mutex>
#include <optional>
#include <unordered_map>
#include <vector>

#include "framework/bundle.h"

namespace tilth {

class KeyedJoin {
 public:
  explicit KeyedJoin(std::size_t slots) : slots_(slots) {}

  // The complete set (ordered by slot) when this arrival completes it.
  std::optional<std::vector<BundlePtr>> add(std::uint64_t sequence, std::size_t slot,
                                            BundlePtr bundle);
  std::size_t pending() const;

 private:
  struct Pending {
    std::vector<BundlePtr> bundles;
    std::size_t missing;
  };

  const std::size_t slots_;
  mutable std::mutex mutex_;
  std::unordered_map<std::uint64_t, Pending> pending_;
};

}  // namespace tilth
