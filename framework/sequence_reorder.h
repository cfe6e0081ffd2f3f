// Releases items in sequence order, whatever order they arrive in: what makes
// stateful stages and sinks see frames 0, 1, 2, ... Invariant: every sequence number
// arrives exactly once (skipped frames arrive as empty bundles).
#pragma once

#include <cstdint>
#include <map>
#include <vector>

namespace tilth {

template <class T>
class SequenceReorder {
 public:
  // The items now releasable, in order (possibly none).
  std::vector<T> push(std::uint64_t sequence, T item) {
    waiting_.emplace(sequence, std::move(item));
    std::vector<T> ready;
    for (auto it = waiting_.begin(); it != waiting_.end() && it->first == next_;
         it = waiting_.erase(it)) {
      ready.push_back(std::move(it->second));
      ++next_;
    }
    return ready;
  }
  std::size_t waiting() const { return waiting_.size(); }

 private:
  std::uint64_t next_ = 0;
  std::map<std::uint64_t, T> waiting_;
};

}  // namespace tilth
