// What travels on an edge. Every concrete message type has a stable type name that the
// graph loader uses to check that an edge connects compatible ports.
#pragma once

#include <string>
#include <string_view>

namespace tilth {

class Message {
 public:
  virtual ~Message();
  virtual std::string_view type_name() const = 0;
  // One line for logs and console sinks.
  virtual std::string summary() const;
};

// Base for concrete messages: `struct Foo : MessageOf<Foo> { static constexpr
// std::string_view kTypeName = "vendor.Foo"; ... };`
template <class Derived>
class MessageOf : public Message {
 public:
  std::string_view type_name() const final { return Derived::kTypeName; }
};

}  // namespace tilth
