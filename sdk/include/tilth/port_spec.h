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

  template <class T>
  static PortSpec of(std::string name, std::string description) {
    return {std::move(name), std::string(T::kTypeName), std::move(description)};
  }
  static PortSpec any(std::string name, std::string description) {
    return {std::move(name), std::string(kAnyType), std::move(description)};
  }

  bool accepts(std::string_view message_type) const {
    return type == kAnyType || type == message_type;
  }
};

}  // namespace tilth
