#include "camera_session.h"

#include <algorithm>

namespace tilth::aravis {
namespace {

using namespace std::chrono_literals;

// Longest wait without looking at the stream: bounds the delay when a buffer's
// notification arrives before Aravis has queued the buffer.
constexpr auto kLookAgain = 10ms;
constexpr auto kFirstReopenDelay = 200ms;
constexpr auto kLongestReopenDelay = 2s;

std::string milliseconds(std::chrono::steady_clock::duration duration) {
  return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(duration).count()) +
         " ms";
}

}  // namespace

CameraSession::CameraSession(CameraSettings settings, Logger log)
    : settings_(std::move(settings)), log_(std::move(log)) {
  active_ = std::make_unique<CameraConnection>(settings_, log_, notifier());
  const auto now = Clock::now();
  adopt_connection(now);
  worker_ = std::thread([this] { reopen_in_background(); });
}

CameraSession::~CameraSession() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
    interrupted_ = true;
  }
  wake_worker_.notify_all();
  wake_.notify_all();
  worker_.join();
  active_.reset();
  reopened_.reset();
  to_close_.clear();
}

void CameraSession::interrupt() {
  {
    std::lock_guard lock(mutex_);
    interrupted_ = true;
  }
  wake_.notify_all();
}

CameraConnection::Notify CameraSession::notifier() {
  return [this] {
    {
      std::lock_guard lock(mutex_);
      ++events_;
    }
    wake_.notify_all();
  };
}

void CameraSession::use_timing(const CameraDescription& description) {
  period_ = description.frame_rate_hz > 0.0
                ? std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(1.0 / description.frame_rate_hz))
                : Clock::duration(1s);
  timeout_ = settings_.timeout.count() > 0 ? Clock::duration(settings_.timeout) : 2 * period_;
}

bool CameraSession::next(PoppedBuffer& frame) {
  frame.reset();
  for (;;) {
    const auto now = Clock::now();
    std::uint64_t seen_events = 0;
    {
      std::lock_guard lock(mutex_);
      if (interrupted_) return false;
      seen_events = events_;
    }
    if (!active_) adopt_connection(now);
    if (active_) {
      if (PoppedBuffer complete = take_next_complete()) {
        if (!streaming_) {
          log_.info(stopped_at_ == Clock::time_point{}
                        ? "first frame from " + description_.label
                        : "streaming again from " + description_.label + ", " +
                              milliseconds(now - stopped_at_) + " after the last frame");
        }
        streaming_ = true;
        problem_.clear();
        last_frame_ = watch_from_ = now;
        underruns_watched_ = active_->underruns();
        frame = std::move(complete);
        return true;
      }
      watch_silence(now);
    }
    auto wake_at = now + kLookAgain;
    if (active_) {
      wake_at = std::min(
          wake_at, streaming_ ? last_frame_ + timeout_ : watch_from_ + settings_.reopen_after);
    }
    if (!streaming_) {
      if (now >= next_empty_due_) {
        next_empty_due_ += period_;
        if (next_empty_due_ <= now) next_empty_due_ = now + period_;
        return true;
      }
      wake_at = std::min(wake_at, next_empty_due_);
    }
    wait_until(wake_at, seen_events);
  }
}

PoppedBuffer CameraSession::take_next_complete() {
  while (PoppedBuffer buffer = active_->try_pop()) {
    if (arv_buffer_get_status(buffer.get()) == ARV_BUFFER_STATUS_SUCCESS) {
      counters_.complete_arrived(arv_buffer_get_frame_id(buffer.get()), active_->underruns());
      return buffer;
    }
    counters_.incomplete_arrived();  // and back to the stream
  }
  return {};
}

// No frame waiting: is the camera silent, starved of buffers, or gone?
void CameraSession::watch_silence(Clock::time_point now) {
  if (active_->control_lost()) {
    lose("camera " + description_.label + " stopped answering (control lost)", now);
    return;
  }
  // Frames arrive, but every buffer is held downstream: late frames, not a lost camera.
  const bool starved = active_->underruns() != underruns_watched_;
  if (streaming_ && now - last_frame_ >= timeout_) {
    streaming_ = false;
    stopped_at_ = now;
    next_empty_due_ = now;
    problem_ =
        starved ? "every stream buffer is held downstream: frames dropped as late"
                : "no frame from " + description_.label + " for " + milliseconds(now - last_frame_);
    log_.warning(problem_);
  }
  if (!streaming_ && now - watch_from_ >= settings_.reopen_after) {
    if (starved) {
      watch_from_ = now;
      underruns_watched_ = active_->underruns();
    } else {
      lose("no frame from " + description_.label + " for " + milliseconds(now - last_frame_), now);
    }
  }
}

void CameraSession::lose(const std::string& reason, Clock::time_point now) {
  log_.warning(reason + "; the camera counts as lost, reopening it in the background");
  if (streaming_) {
    stopped_at_ = now;
    next_empty_due_ = now;
  }
  streaming_ = false;
  problem_ = reason;
  {
    std::lock_guard lock(mutex_);
    to_close_.push_back(std::move(active_));
    reopen_wanted_ = true;
  }
  wake_worker_.notify_all();
}

void CameraSession::adopt_connection(Clock::time_point now) {
  if (!active_) {
    std::lock_guard lock(mutex_);
    if (!reopened_) return;
    active_ = std::move(reopened_);
  }
  const bool first = description_.label.empty();
  description_ = active_->description();
  use_timing(description_);
  counters_.new_stream();
  last_frame_ = watch_from_ = now;
  underruns_watched_ = 0;
  if (first) next_empty_due_ = now + period_;
  problem_ = first ? "waiting for the first frame" : "reopened; waiting for the first frame";
  if (!first) log_.info("reopened " + description_.label);
}

void CameraSession::wait_until(Clock::time_point when, std::uint64_t seen_events) {
  std::unique_lock lock(mutex_);
  wake_.wait_until(lock, when, [&] { return interrupted_ || events_ != seen_events; });
}

void CameraSession::reopen_in_background() {
  std::unique_lock lock(mutex_);
  Clock::duration delay = kFirstReopenDelay;
  for (;;) {
    wake_worker_.wait(
        lock, [&] { return stopping_ || !to_close_.empty() || (reopen_wanted_ && !reopened_); });
    if (!to_close_.empty()) {
      auto closing = std::move(to_close_);
      to_close_.clear();
      lock.unlock();
      closing.clear();  // stops acquisition: slow when the camera is gone
      lock.lock();
      continue;
    }
    if (stopping_) return;
    lock.unlock();
    std::unique_ptr<CameraConnection> connection;
    std::string failure;
    try {
      connection = std::make_unique<CameraConnection>(settings_, log_, notifier());
    } catch (const std::exception& error) {
      failure = error.what();
    }
    lock.lock();
    if (connection) {
      reopened_ = std::move(connection);
      reopen_wanted_ = false;
      reopen_problem_.clear();
      delay = kFirstReopenDelay;
      ++events_;
      wake_.notify_all();
      continue;
    }
    if (failure != reopen_problem_) {
      log_.warning("reopening failed: " + failure + " (retrying with growing pauses, up to " +
                   milliseconds(kLongestReopenDelay) + ")");
    }
    reopen_problem_ = failure;
    wake_worker_.wait_for(lock, delay, [&] { return stopping_; });
    delay = std::min(2 * delay, Clock::duration(kLongestReopenDelay));
  }
}

void CameraSession::fill_status(CameraStatus& status) const {
  status.streaming = streaming_;
  status.problem = problem_;
  if (!streaming_ && !active_) {
    std::lock_guard lock(mutex_);
    if (!reopen_problem_.empty()) status.problem += "; reopening failed: " + reopen_problem_;
  }
  counters_.fill(status);
}

}  // namespace tilth::aravis
