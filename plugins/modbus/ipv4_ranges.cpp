#include "ipv4_ranges.h"

#include <arpa/inet.h>

#include <charconv>

#include "tilth/error.h"

namespace tilth::modbus {

namespace {

std::string address_text(std::uint32_t address) {
  in_addr network_order{htonl(address)};
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &network_order, text, sizeof text);
  return text;
}

}  // namespace

std::uint32_t Ipv4Ranges::mask(int prefix_length) {
  return prefix_length == 0 ? 0 : ~std::uint32_t{0} << (32 - prefix_length);
}

Ipv4Ranges Ipv4Ranges::parse(const std::string& parameter, const nlohmann::json& value) {
  const nlohmann::json entries = value.is_array() ? value : nlohmann::json::array({value});
  Ipv4Ranges parsed;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const nlohmann::json& entry = entries[i];
    const std::string where =
        "parameter '" + parameter + "'" + (value.is_array() ? "/" + std::to_string(i) : "");
    const std::string expected =
        "expected an IPv4 address such as 192.168.1.10 or a CIDR block such as 192.168.1.0/24";
    if (!entry.is_string()) throw Error(where + ": " + expected + ", got " + entry.dump());
    const std::string text = entry.get<std::string>();
    const std::size_t slash = text.find('/');
    const std::string address = text.substr(0, slash);
    Range range;
    if (slash != std::string::npos) {
      const char* first = text.data() + slash + 1;
      const char* last = text.data() + text.size();
      const auto [end, error] = std::from_chars(first, last, range.prefix_length);
      if (error != std::errc() || end != last || first == last || range.prefix_length < 0 ||
          range.prefix_length > 32) {
        throw Error(where + ": " + expected + " (prefix length 0..32), got '" + text + "'");
      }
    }
    in_addr network_order{};
    if (inet_pton(AF_INET, address.c_str(), &network_order) != 1) {
      throw Error(where + ": " + expected + ", got '" + text + "'");
    }
    const std::uint32_t host_order = ntohl(network_order.s_addr);
    range.network = host_order & mask(range.prefix_length);
    if (range.network != host_order) {
      throw Error(where + ": '" + text + "' has host bits set (expected " +
                  address_text(range.network) + "/" + std::to_string(range.prefix_length) + ")");
    }
    parsed.ranges_.push_back(range);
  }
  return parsed;
}

bool Ipv4Ranges::contains(std::uint32_t address) const {
  for (const Range& range : ranges_) {
    if ((address & mask(range.prefix_length)) == range.network) return true;
  }
  return false;
}

std::string Ipv4Ranges::text() const {
  std::string joined;
  for (const Range& range : ranges_) {
    if (!joined.empty()) joined += ", ";
    joined += address_text(range.network);
    if (range.prefix_length != 32) joined += "/" + std::to_string(range.prefix_length);
  }
  return joined;
}

}  // namespace tilth::modbus
