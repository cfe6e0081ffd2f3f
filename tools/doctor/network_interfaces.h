// The host's IPv4 network interfaces, as a GigE Vision camera's packets meet them: name,
// address, netmask and MTU.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tilth::doctor {

struct NetworkInterface {
  std::string name;
  std::uint32_t address = 0;  // host byte order
  std::uint32_t netmask = 0;
  int mtu = 0;

  bool subnet_holds(std::uint32_t other) const { return (other & netmask) == (address & netmask); }
};

std::vector<NetworkInterface> ipv4_interfaces();

// The interface whose subnet holds `address` (host byte order), the narrowest if several.
std::optional<NetworkInterface> interface_for(const std::vector<NetworkInterface>& interfaces,
                                              std::uint32_t address);

std::string ipv4_text(std::uint32_t address);
// Host byte order; nullopt when `text` is no dotted IPv4 address.
std::optional<std::uint32_t> parse_ipv4(const std::string& text);

}  // namespace tilth::doctor
