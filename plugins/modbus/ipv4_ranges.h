// A set of IPv4 addresses written as single addresses or CIDR blocks ("192.168.1.10",
// "192.168.1.0/24"), as the Modbus server's `plc_address` and `allow` parameters name
// them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace tilth::modbus {

class Ipv4Ranges {
 public:
  Ipv4Ranges() = default;
  // `value` is one string or an array of strings; throws tilth::Error naming
  // `parameter`, the entry's index and what was expected.
  static Ipv4Ranges parse(const std::string& parameter, const nlohmann::json& value);

  // `address` in host byte order.
  bool contains(std::uint32_t address) const;
  bool empty() const { return ranges_.empty(); }
  // The ranges as written in a graph file, comma separated.
  std::string text() const;

 private:
  struct Range {
    std::uint32_t network = 0;  // host byte order, host bits 0
    int prefix_length = 32;
  };
  static std::uint32_t mask(int prefix_length);

  std::vector<Range> ranges_;
};

}  // namespace tilth::modbus
