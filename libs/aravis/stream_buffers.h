// The buffers of one stream: allocated once, pushed to the stream, and lent out as the
// pixels of cv::Mats without copying. A lent buffer goes back to its stream when the
// last cv::Mat sharing it is released, on whichever thread that happens; the stream is
// kept (and with it its buffers) until then, even when the camera has been closed.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include <arv.h>
#include <opencv2/core/mat.hpp>

namespace tilth::aravis {

class StreamBuffers : public std::enable_shared_from_this<StreamBuffers> {
 public:
  // Takes a reference on `stream` and pushes `count` buffers of `bytes` to it.
  static std::shared_ptr<StreamBuffers> create(ArvStream* stream, std::size_t count,
                                               std::size_t bytes);
  ~StreamBuffers();
  StreamBuffers(const StreamBuffers&) = delete;
  StreamBuffers& operator=(const StreamBuffers&) = delete;

  // `pixels` (headers over memory inside `buffer`, a buffer popped from this stream: one
  // per part taken from it) now own `buffer` together: any of them or of their copies
  // keeps the buffer from the stream.
  void lend(ArvBuffer* buffer, std::span<cv::Mat* const> pixels);
  // Returns a popped buffer that is not lent (an incomplete frame, a dropped one).
  void give_back(ArvBuffer* buffer);

  std::size_t count() const { return slots_.size(); }

 private:
  struct Slot;
  class Allocator;
  explicit StreamBuffers(ArvStream* stream);

  ArvStream* stream_;
  std::vector<std::unique_ptr<Slot>> slots_;
};

// A buffer popped from a stream: given back when this goes out of scope, unless its
// pixels were lent.
class PoppedBuffer {
 public:
  PoppedBuffer() = default;
  PoppedBuffer(std::shared_ptr<StreamBuffers> owner, ArvBuffer* buffer)
      : owner_(std::move(owner)), buffer_(buffer) {}
  PoppedBuffer(PoppedBuffer&& other) noexcept
      : owner_(std::move(other.owner_)), buffer_(std::exchange(other.buffer_, nullptr)) {}
  PoppedBuffer& operator=(PoppedBuffer&& other) noexcept {
    reset();
    owner_ = std::move(other.owner_);
    buffer_ = std::exchange(other.buffer_, nullptr);
    return *this;
  }
  ~PoppedBuffer() { reset(); }

  ArvBuffer* get() const { return buffer_; }
  explicit operator bool() const { return buffer_ != nullptr; }
  // See StreamBuffers::lend; the buffer is then no longer this object's to give back.
  void lend_to(std::span<cv::Mat* const> pixels) {
    owner_->lend(std::exchange(buffer_, nullptr), pixels);
  }
  void lend_to(cv::Mat& pixels) {
    cv::Mat* const one[] = {&pixels};
    lend_to(one);
  }
  void reset() {
    if (buffer_ != nullptr) owner_->give_back(std::exchange(buffer_, nullptr));
  }

 private:
  std::shared_ptr<StreamBuffers> owner_;
  ArvBuffer* buffer_ = nullptr;
};

}  // namespace tilth::aravis
