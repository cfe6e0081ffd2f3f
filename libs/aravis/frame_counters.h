// A camera's frame counts as tilth::CameraStatus reports them, from the buffers its
// stream delivers.
//
// Only a complete buffer's block id can be trusted (Aravis takes it from the frame's
// leader packet), and an incomplete frame comes out only when Aravis stops waiting for its
// packets (100 ms), after the complete frames behind it. So the frames missing from a
// stream are counted as a whole: the gaps in the block ids of its complete frames (16-bit
// ids wrap from 65535 to 1), less the incomplete frames that came out between its first
// and its latest complete frame. Of those, a gap found after the stream had no free buffer
// for a while (its underrun count grew) is late; the rest lost. An incomplete frame still
// on its way makes `lost` one too high for up to 100 ms.
#pragma once

#include <cstdint>
#include <optional>

#include "tilth/messages/camera_status.h"

namespace tilth::aravis {

class FrameCounters {
 public:
  // A new stream: its block ids start afresh and its underrun count from zero.
  void new_stream();
  void incomplete_arrived();
  // `stream_underruns`: the stream's underrun count (which Aravis counts per packet).
  void complete_arrived(std::uint64_t block_id, std::uint64_t stream_underruns);

  void fill(CameraStatus& status) const;

 private:
  struct StreamCounts {
    std::uint64_t skipped = 0;  // block ids missing between complete frames
    std::uint64_t incomplete = 0;
    std::uint64_t incomplete_between = 0;  // after the first complete frame, before the latest
    std::uint64_t incomplete_since_complete = 0;
    std::uint64_t skipped_while_starved = 0;
    std::uint64_t lost() const;
    std::uint64_t late() const;
  };

  std::uint64_t completed_ = 0;
  std::uint64_t incomplete_ = 0;  // of previous streams
  std::uint64_t lost_ = 0;
  std::uint64_t late_ = 0;
  StreamCounts stream_;
  std::optional<std::uint64_t> last_complete_id_;
  std::uint64_t underruns_at_last_gap_ = 0;
};

}  // namespace tilth::aravis
