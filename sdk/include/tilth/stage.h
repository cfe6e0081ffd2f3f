// The three kinds of stage a plugin implements. A source has only outputs, a sink only
// inputs, a transform both. Stages never keep a borrowed Frame past the call.
#pragma once

#include <atomic>

#include "tilth/frame.h"

namespace tilth {

class Stage {
 public:
  virtual ~Stage();
  // Called once after the last frame: flush files, close connections.
  virtual void finish() {}
};

class Source : public Stage {
 public:
  ~Source() override;
  // Fills the outputs with the next frame; returns false at the end of the stream.
  // May block (a camera waiting for a frame); interrupt() must make it return soon.
  virtual bool produce(Frame& frame) = 0;
  // Called from another thread when the graph stops.
  virtual void interrupt() {}
};

class Transform : public Stage {
 public:
  ~Transform() override;
  // Reads inputs, sets outputs. An output left unset makes the frame skip the stages
  // that need it. Throwing reports the error with the node name and frame id.
  virtual void process(Frame& frame) = 0;
};

class Sink : public Stage {
 public:
  ~Sink() override;
  virtual void consume(const Frame& frame) = 0;
  // The frame did not reach this sink: an upstream stage failed or produced nothing.
  virtual void skipped(const FrameInfo& /*info*/) {}
};

}  // namespace tilth
