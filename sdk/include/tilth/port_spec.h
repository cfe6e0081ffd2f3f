// The declaration of one named, typed stage port.
#pragma once

#include <string>
#include <string_view>

namespace tilth {

struct PortSpec {
  // An input of this type accepts any message.
  static constexpr std::string_view kAnyType = "*";

  std::string name;
  std::string type;  // a message type name
  std::string description;
  // An optional input may be left unconnected, and the stage still runs when it has no
  // data for a frame (its packet is then empty). Required inputs must be connected, and
  // a frame without data on one skips the stage.
  bool required = true;

  template <class T>
  static PortSpec of(std::string name, std::string description) {
    return {std::move(name), std::string(T::kTypeName), std::move(description), true};
  }
  static PortSpec any(std::string name, std::string description) {
    return {std::move(name), std::string(kAnyType), std::move(description), true};
  }

  PortSpec& optional() {
    required = false;
    return *this;
  }

  bool accepts(std::string_view message_type) const {
    return type == kAnyType || type == message_type;
  }
};

}  // namespace tilth
