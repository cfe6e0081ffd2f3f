// One camera kept streaming for a source stage, through losses.
//
//   next() ── frame ─────────────────────────────────▶ stage: image + status
//     │ no frame for the timeout (two frame periods)
//     ▼
//   silent ── once per frame period: no image ───────▶ stage: status only, streaming=false
//     │ still no frame after reopen_after, or control lost     (frames resume: streaming)
//     ▼
//   lost ── once per frame period: no image; a background thread closes the camera and
//     │     reopens it with growing pauses
//     ▼ reopened
//   waiting for the first frame (still once per period) ── frame ──▶ streaming again
//
// A camera that sends while the graph holds every stream buffer is not lost: its frames
// are late, and it is not reopened.
//
// Invariant: while not streaming, next() returns once per frame period whatever the
// camera does, and at once after interrupt(); closing or opening a camera, which can take
// seconds, never happens on the thread that calls next().
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "camera_connection.h"
#include "camera_settings.h"
#include "frame_counters.h"
#include "stream_buffers.h"
#include "tilth/log.h"
#include "tilth/messages/camera_status.h"

namespace tilth::aravis {

class CameraSession {
 public:
  // Opens the camera now, so that a missing camera or a setting it refuses stops the
  // graph before it runs (tilth::Error).
  CameraSession(CameraSettings settings, Logger log);
  ~CameraSession();
  CameraSession(const CameraSession&) = delete;
  CameraSession& operator=(const CameraSession&) = delete;

  // The next complete frame; an empty buffer when there is none to give (the camera is
  // silent, lost, or not streaming yet). False once interrupted. Call from one thread.
  bool next(PoppedBuffer& frame);
  // The camera the last frame came from; valid until the next call of next().
  const CameraDescription& description() const { return description_; }
  // streaming, problem and the frame counters; `camera` is left to the caller.
  void fill_status(CameraStatus& status) const;
  // From any thread: next() returns false from now on.
  void interrupt();

 private:
  using Clock = std::chrono::steady_clock;

  PoppedBuffer take_next_complete();
  void watch_silence(Clock::time_point now);
  void lose(const std::string& reason, Clock::time_point now);
  // Starts using the first connection, or the one reopened in the background, if any.
  void adopt_connection(Clock::time_point now);
  void wait_until(Clock::time_point when, std::uint64_t seen_events);
  void reopen_in_background();
  CameraConnection::Notify notifier();
  void use_timing(const CameraDescription& description);

  const CameraSettings settings_;
  const Logger log_;

  mutable std::mutex mutex_;
  std::condition_variable wake_;         // next(): a buffer, control lost, reopened, interrupt
  std::condition_variable wake_worker_;  // the reopening thread
  std::uint64_t events_ = 0;
  bool interrupted_ = false;
  bool stopping_ = false;
  bool reopen_wanted_ = false;
  std::unique_ptr<CameraConnection> reopened_;
  std::vector<std::unique_ptr<CameraConnection>> to_close_;
  std::string reopen_problem_;

  // The thread calling next() only.
  std::unique_ptr<CameraConnection> active_;
  CameraDescription description_;
  FrameCounters counters_;
  bool streaming_ = false;
  std::string problem_;
  Clock::duration period_{};
  Clock::duration timeout_{};
  Clock::time_point last_frame_;         // or when the connection started
  Clock::time_point watch_from_;         // silence counted from here
  std::uint64_t underruns_watched_ = 0;  // the stream's underruns at watch_from_
  Clock::time_point stopped_at_;         // when frames stopped, for the log
  Clock::time_point next_empty_due_;     // while not streaming

  std::thread worker_;  // last: started when everything it uses exists
};

}  // namespace tilth::aravis
