// Lets frames into a running graph.
//
//   source 0 --offer--> [waiting 0] --+
//                                     +--(all waiting, in flight < max)--> admit(seq, ...)
//   source 1 --offer--> [waiting 1] --+                ^
//                                     complete() ------+  (a frame left the graph)
//
// A frame is one packet bundle from every source; it gets the next sequence number when
// it is admitted, so sequence numbers are dense and the same for all sources of a frame
// (the join key). Each source has one waiting place. When it is taken, `block` makes the
// offering source wait (replay: nothing is lost) and `drop_oldest` replaces the waiting
// bundle with the new one (live: the freshest frame goes next).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "framework/graph_spec.h"

namespace tilth {

struct Bundle;

class FrameAdmission {
 public:
  using Admit = std::function<void(std::uint64_t sequence, std::vector<std::shared_ptr<Bundle>>)>;

  // `admit` is called outside the lock, possibly from several threads at once.
  FrameAdmission(std::size_t sources, std::size_t max_in_flight, FullPolicy policy, Admit admit,
                 std::optional<std::uint64_t> frame_limit = std::nullopt);

  // Returns false once admission is closed; the bundle is then discarded.
  bool offer(std::size_t source, std::shared_ptr<Bundle> bundle);
  // The source has no more frames.
  void end_of_stream(std::size_t source);
  // A frame admitted earlier has left the graph.
  void complete();
  // No frame is admitted after this; waiting bundles are discarded, blocked sources return.
  void close();
  // Blocks until admission is closed and no frame is in flight.
  void wait_until_drained();

  std::uint64_t admitted() const;
  std::uint64_t dropped() const;
  std::uint64_t in_flight() const;

 private:
  using Batch = std::vector<std::pair<std::uint64_t, std::vector<std::shared_ptr<Bundle>>>>;
  Batch take_admissible_locked();
  void admit_all(Batch batch);

  const std::size_t max_in_flight_;
  const FullPolicy policy_;
  const Admit admit_;
  const std::optional<std::uint64_t> frame_limit_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::shared_ptr<Bundle>> waiting_;  // one place per source
  std::vector<bool> ended_;
  bool closed_ = false;
  std::uint64_t next_sequence_ = 0;
  std::uint64_t in_flight_ = 0;
  std::uint64_t dropped_ = 0;
};

}  // namespace tilth
