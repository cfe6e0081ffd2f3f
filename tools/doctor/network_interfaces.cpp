#include "network_interfaces.h"

#include <cstring>

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <unistd.h>

namespace tilth::doctor {
namespace {

int mtu_of(const char* name) {
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd < 0) return 0;
  ifreq request{};
  std::strncpy(request.ifr_name, name, IFNAMSIZ - 1);
  const int mtu = ioctl(fd, SIOCGIFMTU, &request) == 0 ? request.ifr_mtu : 0;
  close(fd);
  return mtu;
}

}  // namespace

std::vector<NetworkInterface> ipv4_interfaces() {
  std::vector<NetworkInterface> interfaces;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return interfaces;
  for (const ifaddrs* entry = list; entry != nullptr; entry = entry->ifa_next) {
    if (entry->ifa_addr == nullptr || entry->ifa_addr->sa_family != AF_INET ||
        entry->ifa_netmask == nullptr || (entry->ifa_flags & IFF_UP) == 0) {
      continue;
    }
    NetworkInterface interface;
    interface.name = entry->ifa_name;
    interface.address =
        ntohl(reinterpret_cast<const sockaddr_in*>(entry->ifa_addr)->sin_addr.s_addr);
    interface.netmask =
        ntohl(reinterpret_cast<const sockaddr_in*>(entry->ifa_netmask)->sin_addr.s_addr);
    interface.mtu = mtu_of(entry->ifa_name);
    interfaces.push_back(interface);
  }
  freeifaddrs(list);
  return interfaces;
}

std::optional<NetworkInterface> interface_for(const std::vector<NetworkInterface>& interfaces,
                                              std::uint32_t address) {
  std::optional<NetworkInterface> best;
  for (const auto& interface : interfaces) {
    if (interface.subnet_holds(address) && (!best || interface.netmask > best->netmask)) {
      best = interface;
    }
  }
  return best;
}

std::string ipv4_text(std::uint32_t address) {
  in_addr raw{htonl(address)};
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &raw, text, sizeof text);
  return text;
}

std::optional<std::uint32_t> parse_ipv4(const std::string& text) {
  in_addr raw{};
  if (inet_pton(AF_INET, text.c_str(), &raw) != 1) return std::nullopt;
  return ntohl(raw.s_addr);
}

}  // namespace tilth::doctor
