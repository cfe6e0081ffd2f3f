// One frame as a stage sees it during one call: the input packets (joined by the
// runtime) and the outputs it sets. Ports are addressed by their index in the stage's
// descriptor. Inputs are borrowed for the call; share() an input to keep it.
#pragma once

#include <cstddef>
#include <memory>
#include <span>

#include "tilth/packet.h"

namespace tilth {

class Frame {
 public:
  Frame(FrameInfo info, std::span<const Packet> inputs, std::span<Packet> outputs)
      : info_(info), inputs_(inputs), outputs_(outputs) {}

  const FrameInfo& info() const { return info_; }
  // Sources set the source's frame id and capture times.
  void set_capture(std::uint64_t frame_id, std::int64_t device_timestamp_ns,
                   std::int64_t host_timestamp_ns);

  const Packet& input(std::size_t port) const;
  template <class T>
  const T& input(std::size_t port) const {
    return input(port).get<T>();
  }
  template <class T>
  std::shared_ptr<const T> share_input(std::size_t port) const {
    return input(port).share<T>();
  }

  void set_output(std::size_t port, std::shared_ptr<const Message> message);
  template <class T>
  void emit(std::size_t port, T message) {
    set_output(port, std::make_shared<const T>(std::move(message)));
  }

 private:
  FrameInfo info_;
  std::span<const Packet> inputs_;
  std::span<Packet> outputs_;
};

}  // namespace tilth
