#include "frame_counters.h"

#include <algorithm>

namespace tilth::aravis {
namespace {

constexpr std::uint64_t kLargestShortId = 0xffff;  // GigE Vision 1: 1..65535, then 1 again

// Block ids between `last` and `id` that did not come whole. An id that is not newer
// (Aravis discards late blocks) means the camera restarted its count: nothing skipped.
std::uint64_t skipped_between(std::uint64_t last, std::uint64_t id) {
  if (id > last) return id - last - 1;
  if (last <= kLargestShortId && id >= 1) {
    const std::uint64_t wrapped = (kLargestShortId - last) + (id - 1);
    if (wrapped < kLargestShortId / 2) return wrapped;
  }
  return 0;
}

}  // namespace

std::uint64_t FrameCounters::StreamCounts::late() const {
  const std::uint64_t missing = skipped - std::min(skipped, incomplete_between);
  return std::min(skipped_while_starved, missing);
}

std::uint64_t FrameCounters::StreamCounts::lost() const {
  return skipped - std::min(skipped, incomplete_between) - late();
}

void FrameCounters::incomplete_arrived() {
  ++stream_.incomplete;
  if (last_complete_id_) ++stream_.incomplete_since_complete;
}

void FrameCounters::new_stream() {
  incomplete_ += stream_.incomplete;
  lost_ += stream_.lost();
  late_ += stream_.late();
  stream_ = {};
  last_complete_id_.reset();
  underruns_at_last_gap_ = 0;
}

void FrameCounters::complete_arrived(std::uint64_t block_id, std::uint64_t stream_underruns) {
  if (last_complete_id_) {
    const std::uint64_t skipped = skipped_between(*last_complete_id_, block_id);
    if (skipped > 0) {
      stream_.skipped += skipped;
      if (stream_underruns > underruns_at_last_gap_) stream_.skipped_while_starved += skipped;
      underruns_at_last_gap_ = stream_underruns;
    }
  }
  stream_.incomplete_between += stream_.incomplete_since_complete;
  stream_.incomplete_since_complete = 0;
  last_complete_id_ = block_id;
  ++completed_;
}

void FrameCounters::fill(CameraStatus& status) const {
  status.completed = completed_;
  status.incomplete = incomplete_ + stream_.incomplete;
  status.lost = lost_ + stream_.lost();
  status.late = late_ + stream_.late();
}

}  // namespace tilth::aravis
