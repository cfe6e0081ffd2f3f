// Fuzz target: the Modbus TCP server's handling of what a client sends. The server is
// only reachable through a socket (its framing, checks and replies live in its poll
// thread), so it runs here as in a graph, on a free loopback port, and each input is
// the byte stream of one client connection: connect, send the input, close the sending
// side, read every reply until the server closes. A bug is a crash or sanitizer report
// in the server thread, a connection the server does not close after the client's end
// of stream, or a reply that is not a whole Modbus TCP frame answering the request at
// the same position (same transaction id and unit, same function code or the exception
// to it).
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <arpa/inet.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "latest_measurement.h"
#include "modbus_server.h"
#include "tilth/error.h"
#include "tilth/log.h"

namespace {

using tilth::modbus::LatestMeasurement;
using tilth::modbus::ModbusServer;
using tilth::modbus::ServerOptions;

constexpr std::size_t kMbapSize = 7;
constexpr int kCloseTimeoutMs = 10000;
constexpr std::size_t kMaxReplyBytes = 1 << 16;

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "modbus_request: %s\n", what);
  std::abort();
}

sockaddr_in loopback(int port) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return address;
}

// A port nothing listens on now: the kernel's choice for a socket bound to port 0.
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address = loopback(0);
  socklen_t length = sizeof address;
  if (fd == -1 || ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    fail("cannot find a free loopback port");
  }
  ::close(fd);
  return ntohs(address.sin_port);
}

struct Server {
  LatestMeasurement latest{std::chrono::milliseconds(500)};
  int port = 0;
  std::unique_ptr<ModbusServer> server;

  Server() {
    // The server logs every client it refuses; the fuzzer's output stays readable.
    tilth::set_log_handler([](tilth::LogLevel, std::string_view, std::string_view) {});
    for (int attempt = 0; attempt < 5 && !server; ++attempt) {
      ServerOptions options;
      options.address = "127.0.0.1";
      options.port = free_port();
      options.unit_id = 1;
      options.base_register = 100;
      try {
        server = std::make_unique<ModbusServer>(options, latest, tilth::Logger("fuzz"));
        port = options.port;
      } catch (const tilth::Error&) {  // the port was taken in between: another one
      }
    }
    if (!server) fail("cannot start the Modbus server");
  }
};

std::uint16_t word_at(const std::vector<std::uint8_t>& bytes, std::size_t offset) {
  return static_cast<std::uint16_t>(bytes[offset] << 8 | bytes[offset + 1]);
}

// The whole Modbus TCP frames at the start of `bytes` (by their MBAP length field).
std::vector<std::vector<std::uint8_t>> frames_of(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::vector<std::uint8_t>> frames;
  std::size_t at = 0;
  while (bytes.size() - at >= kMbapSize) {
    const std::size_t length = word_at(bytes, at + 4);
    if (length < 2 || bytes.size() - at < 6 + length) break;
    frames.emplace_back(bytes.begin() + at, bytes.begin() + at + 6 + length);
    at += 6 + length;
  }
  return frames;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Server server;
  // The client closes first, so each connection leaves a TIME_WAIT (60 s) behind on its
  // side: thousands a second would use up one address's ephemeral ports in seconds. The
  // client therefore connects from the 253 loopback addresses 127.0.0.2 to 127.0.0.254
  // in turn.
  static std::uint32_t connections = 0;
  sockaddr_in source = loopback(0);
  source.sin_addr.s_addr = htonl(INADDR_LOOPBACK + 1 + connections++ % 253);
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const sockaddr_in address = loopback(server.port);
  if (fd == -1 || ::bind(fd, reinterpret_cast<const sockaddr*>(&source), sizeof source) != 0 ||
      ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    fail("cannot connect to the server");
  }
  // The server may close the connection before it has read everything (bytes that are
  // not Modbus TCP): a failed send is the client's loss, not a bug.
  for (std::size_t sent = 0; sent < size;) {
    const ssize_t n = ::send(fd, data + sent, size - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<std::size_t>(n);
  }
  ::shutdown(fd, SHUT_WR);

  std::vector<std::uint8_t> replies;
  for (;;) {
    pollfd polled{fd, POLLIN, 0};
    if (::poll(&polled, 1, kCloseTimeoutMs) != 1) {
      tcp_info info{};
      socklen_t length = sizeof info;
      ::getsockopt(fd, IPPROTO_TCP, TCP_INFO, &info, &length);
      std::fprintf(stderr, "modbus_request: after %zu bytes sent and %zu received, TCP state %u\n",
                   size, replies.size(), static_cast<unsigned>(info.tcpi_state));
      fail("the server kept the connection open");
    }
    std::uint8_t buffer[4096];
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;  // closed (or reset after the bytes it refused)
    replies.insert(replies.end(), buffer, buffer + n);
    if (replies.size() > kMaxReplyBytes) fail("more reply bytes than requests could ask for");
  }
  ::close(fd);

  const auto requests = frames_of(std::vector<std::uint8_t>(data, data + size));
  const auto answers = frames_of(replies);
  std::size_t answered = 0;
  for (const auto& answer : answers) answered += answer.size();
  if (answered != replies.size()) fail("a reply is not a whole Modbus TCP frame");
  if (answers.size() > requests.size()) fail("more replies than requests");
  for (std::size_t i = 0; i < answers.size(); ++i) {
    const auto& request = requests[i];
    const auto& answer = answers[i];
    if (std::memcmp(answer.data(), request.data(), 4) != 0 || answer[6] != request[6]) {
      fail("a reply's transaction id, protocol id or unit differs from its request's");
    }
    if ((answer[kMbapSize] & 0x7F) != request[kMbapSize]) {
      fail("a reply's function code is neither the request's nor its exception");
    }
  }
  return 0;
}
