// A packet: one message plus the identity and capture times of the frame it came from.
// Copying a packet shares the message (and any cv::Mat in it); pixels are never copied.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "tilth/error.h"
#include "tilth/message.h"

namespace tilth {

struct FrameInfo {
  // Dense, assigned by the runtime when the frame enters the graph; the join key.
  std::uint64_t sequence = 0;
  // The source's own id: a recording's frame index, a camera's block id.
  std::uint64_t frame_id = 0;
  // Capture time on the device's clock and on the host's (CLOCK_REALTIME) clock.
  std::int64_t device_timestamp_ns = 0;
  std::int64_t host_timestamp_ns = 0;
};

class Packet {
 public:
  Packet() = default;
  Packet(FrameInfo info, std::shared_ptr<const Message> message)
      : info_(info), message_(std::move(message)) {}

  const FrameInfo& info() const { return info_; }
  bool empty() const { return message_ == nullptr; }
  const std::shared_ptr<const Message>& message() const { return message_; }

  // The message as T; throws tilth::Error if the packet is empty or holds another type.
  template <class T>
  const T& get() const {
    return *share<T>();
  }
  template <class T>
  std::shared_ptr<const T> share() const {
    if (!message_) throw Error("packet of frame " + std::to_string(info_.frame_id) + " is empty");
    if (message_->type_name() != T::kTypeName) {
      throw Error("packet holds " + std::string(message_->type_name()) + ", not " +
                  std::string(T::kTypeName));
    }
    return std::static_pointer_cast<const T>(message_);
  }

 private:
  FrameInfo info_;
  std::shared_ptr<const Message> message_;
};

}  // namespace tilth
