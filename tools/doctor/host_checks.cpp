#include "host_checks.h"

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/statvfs.h>
#include <unistd.h>

namespace tilth::doctor {
namespace {

constexpr int kCapNetRaw = 13;  // linux/capability.h
constexpr int kModbusPort = 502;

std::string mebibytes(std::uint64_t bytes) {
  std::ostringstream text;
  text.precision(bytes >= (10ull << 20) ? 0 : 1);
  text << std::fixed << static_cast<double>(bytes) / (1 << 20) << " MiB";
  return text.str();
}

// One TCP connection attempt, bounded by `timeout`; the reason on failure.
std::string connect_error(const addrinfo& address, std::chrono::milliseconds timeout) {
  const int fd = socket(address.ai_family, SOCK_STREAM | SOCK_NONBLOCK, 0);
  if (fd < 0) return std::strerror(errno);
  std::string error;
  if (connect(fd, address.ai_addr, address.ai_addrlen) != 0) {
    if (errno != EINPROGRESS) {
      error = std::strerror(errno);
    } else {
      pollfd waiting{fd, POLLOUT, 0};
      const int ready = poll(&waiting, 1, static_cast<int>(timeout.count()));
      int status = 0;
      socklen_t size = sizeof status;
      if (ready == 0) {
        error = "no answer within " + std::to_string(timeout.count()) + " ms";
      } else if (ready < 0 || getsockopt(fd, SOL_SOCKET, SO_ERROR, &status, &size) != 0) {
        error = std::strerror(errno);
      } else if (status != 0) {
        error = std::strerror(status);
      }
    }
  }
  close(fd);
  return error;
}

}  // namespace

Finding check_receive_buffer_limit(std::uint64_t largest_frame_bytes) {
  Finding finding{"net.core.rmem_max"};
  std::ifstream file("/proc/sys/net/core/rmem_max");
  std::uint64_t limit = 0;
  if (!(file >> limit)) {
    finding.verdict = Verdict::kWarning;
    finding.detail = "cannot read /proc/sys/net/core/rmem_max";
    return finding;
  }
  finding.detail = std::to_string(limit) + " bytes (" + mebibytes(limit) + ")";
  if (largest_frame_bytes == 0) return finding;
  finding.detail += "; the largest frame is " + std::to_string(largest_frame_bytes) + " bytes";
  if (limit < largest_frame_bytes) {
    finding.verdict = Verdict::kWarning;
    finding.detail +=
        ": a stream's socket cannot buffer one whole frame, so packets are lost "
        "when the receiving thread is late";
    finding.fix = "sysctl -w net.core.rmem_max=" + std::to_string(4 * largest_frame_bytes) +
                  " (and in /etc/sysctl.d/ to keep it)";
  }
  return finding;
}

Finding check_packet_socket_capability() {
  Finding finding{"packet socket (CAP_NET_RAW)"};
  std::ifstream status("/proc/self/status");
  std::string line;
  std::uint64_t effective = 0;
  while (std::getline(status, line)) {
    if (line.rfind("CapEff:", 0) == 0) effective = std::stoull(line.substr(7), nullptr, 16);
  }
  if ((effective >> kCapNetRaw) & 1u) {
    finding.detail = "held: Aravis receives streams on a packet socket";
    return finding;
  }
  finding.verdict = Verdict::kWarning;
  finding.detail = "not held: Aravis falls back to UDP sockets, which cost more CPU per packet";
  finding.fix =
      "run as the tilth@.service unit does (AmbientCapabilities=CAP_NET_RAW), or "
      "setcap cap_net_raw+ep on the tilth program";
  return finding;
}

Finding check_free_disk(const std::filesystem::path& directory, std::uint64_t min_free_bytes) {
  Finding finding{"free disk"};
  struct statvfs disk {};
  if (statvfs(directory.c_str(), &disk) != 0) {
    finding.verdict = Verdict::kFailed;
    finding.detail = directory.string() + ": " + std::strerror(errno);
    finding.fix = "name an existing directory for recordings with --recordings DIR";
    return finding;
  }
  const std::uint64_t free_bytes = static_cast<std::uint64_t>(disk.f_bavail) * disk.f_frsize;
  finding.detail = directory.string() + ": " + mebibytes(free_bytes) + " free (wanted " +
                   mebibytes(min_free_bytes) + ")";
  if (free_bytes < min_free_bytes) {
    finding.verdict = Verdict::kFailed;
    finding.fix = "free space there, or record elsewhere (--recordings DIR names where)";
  }
  return finding;
}

Finding check_plc(const std::string& address, std::chrono::milliseconds timeout) {
  Finding finding{"PLC " + address};
  std::string host = address;
  std::string port = std::to_string(kModbusPort);
  if (const auto colon = address.rfind(':'); colon != std::string::npos) {
    host = address.substr(0, colon);
    port = address.substr(colon + 1);
  }
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int error = getaddrinfo(host.c_str(), port.c_str(), &hints, &found); error != 0) {
    finding.verdict = Verdict::kFailed;
    finding.detail = "cannot resolve '" + address + "': " + gai_strerror(error);
    finding.fix = "give the PLC as IPv4[:PORT], as the graph's plc_address";
    return finding;
  }
  const std::string error = connect_error(*found, timeout);
  freeaddrinfo(found);
  if (error.empty()) {
    finding.detail = "accepts TCP connections on port " + port;
    return finding;
  }
  finding.verdict = Verdict::kFailed;
  finding.detail = "no TCP connection to port " + port + ": " + error;
  finding.fix = "check the PLC is on, on this subnet, and serves Modbus TCP on that port";
  return finding;
}

}  // namespace tilth::doctor
