// The kinds of stage a plugin implements. A source has only outputs, a sink only inputs,
// a transform both; a synchronizer is a transform whose inputs are not joined by frame.
// Stages never keep a borrowed Frame past the call.
#pragma once

#include <atomic>
#include <cstdint>

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

// Lines up sources that run on their own clocks (free-running cameras) into the graph's
// frames. Its inputs come straight from sources; the runtime hands it each source frame
// as it arrives, one call at a time, and it emits a frame of the graph whenever it has
// matched one. What it emits is admitted like a source's frame (frames in flight,
// when_full), so it is where the sources it lines up enter the graph.
class Synchronizer : public Stage {
 public:
  // The frames one call emits.
  class Output {
   public:
    virtual ~Output();
    // Starts a frame of the graph: set its capture identity and outputs on the Frame
    // returned, which stays valid until accept() returns.
    virtual Frame& emit() = 0;
  };

  ~Synchronizer() override;
  // `arrived` holds one source frame: its packets on the inputs that source feeds, the
  // other inputs empty; arrived.info() is that source's capture identity.
  virtual void accept(const Frame& arrived, Output& output) = 0;
};

}  // namespace tilth
