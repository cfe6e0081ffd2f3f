// The host capture time a recording player stamps its frames with, chosen by the
// parameter `host_time` that every player declares the same way. `replayed` (the
// default) is the host clock when the frame is played, as a live camera's frame is
// stamped, so latencies and ages measured from capture (the runtime's, a sink's, a PLC's)
// mean on a replay what they mean live. `recorded` is the time the recording kept, for a
// graph that converts or re-records a recording and must carry it through.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "tilth/param_spec.h"
#include "tilth/params.h"

namespace tilth {

class ReplayHostTime {
 public:
  // `recorded`: what `recorded` stamps, in the player's terms.
  static ParamSpec param(const std::string& recorded) {
    return ParamSpec::choice("host_time", {"replayed", "recorded"}, "replayed")
        .describe(
            "each frame's host capture time: replayed = when it is played, as a live "
            "camera's, so latencies from capture measure the graph; recorded = " +
            recorded);
  }

  explicit ReplayHostTime(const Params& params)
      : recorded_(params.string("host_time") == "recorded") {}

  // `recorded_ns` when the recorded times are asked for and the recording has one,
  // otherwise the host clock now.
  std::int64_t stamp(std::optional<std::int64_t> recorded_ns) const {
    if (recorded_ && recorded_ns) return *recorded_ns;
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  }

 private:
  bool recorded_;
};

}  // namespace tilth
