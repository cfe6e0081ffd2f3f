// The health of one camera (or of several, combined): whether it streams, why not, and
// its frame counters. Camera sources send one with every frame, and keep sending them
// once per frame period while the camera is lost, so the graph learns of the loss within
// a frame period and the machine is told the measurement is invalid.
#pragma once

#include <cstdint>
#include <string>

#include "tilth/message.h"

namespace tilth {

struct CameraStatus : MessageOf<CameraStatus> {
  static constexpr std::string_view kTypeName = "tilth.CameraStatus";

  std::string camera;            // who: a node name, a device id, or "depth+color"
  bool streaming = false;        // frames arrive; false: lost, reconnecting or not yet started
  std::string problem;           // why not streaming, for the log and the operator
  std::uint64_t completed = 0;   // frames received whole
  std::uint64_t incomplete = 0;  // frames with missing packets, not passed on
  std::uint64_t lost = 0;        // frame ids that never arrived
  std::uint64_t late = 0;        // frames older than the graph could take, dropped

  std::string summary() const override;
};

}  // namespace tilth
