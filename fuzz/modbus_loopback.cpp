#include "modbus_loopback.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "tilth/error.h"
#include "tilth/log.h"

namespace tilth::fuzz {
namespace {

using Clock = std::chrono::steady_clock;

sockaddr_in ipv4(std::uint32_t address, int port) {
  sockaddr_in result{};
  result.sin_family = AF_INET;
  result.sin_port = htons(static_cast<std::uint16_t>(port));
  result.sin_addr.s_addr = htonl(address);
  return result;
}

std::string address_text(const sockaddr_in& address) {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

// Closes its descriptor when it goes.
class Socket {
 public:
  Socket() : fd_(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0)) {}
  ~Socket() {
    if (fd_ != -1) ::close(fd_);
  }
  Socket(const Socket&) = delete;
  Socket& operator=(const Socket&) = delete;
  int fd() const { return fd_; }

 private:
  int fd_;
};

// A port nothing listens on now: the kernel's choice for a socket bound to port 0.
int free_loopback_port() {
  const Socket socket;
  sockaddr_in address = ipv4(INADDR_LOOPBACK, 0);
  socklen_t length = sizeof address;
  if (socket.fd() == -1 ||
      ::bind(socket.fd(), reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::getsockname(socket.fd(), reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    throw Error(std::string("cannot find a free loopback port: ") + std::strerror(errno));
  }
  return ntohs(address.sin_port);
}

// Whether the socket has one of `events` before `deadline`. A signal does not end the wait:
// libFuzzer's -timeout sends SIGALRM every few seconds, with a handler installed without
// SA_RESTART, and poll() then returns EINTR however long it has waited.
bool ready_before(const Socket& socket, short events, Clock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now());
    pollfd polled{socket.fd(), events, 0};
    const int ready = ::poll(&polled, 1, static_cast<int>(std::max<std::int64_t>(left.count(), 0)));
    if (ready != -1) return ready == 1;
    if (errno != EINTR)
      throw Error(std::string("poll on a client connection failed: ") + std::strerror(errno));
  }
}

void connect_from(const Socket& socket, std::uint32_t source, int port,
                  Clock::time_point deadline) {
  const sockaddr_in from = ipv4(source, 0);
  const sockaddr_in to = ipv4(INADDR_LOOPBACK, port);
  const auto failed = [&](int error) {
    return Error("cannot connect from " + address_text(from) + " to " + address_text(to) + ": " +
                 std::strerror(error));
  };
  if (socket.fd() == -1 ||
      ::bind(socket.fd(), reinterpret_cast<const sockaddr*>(&from), sizeof from) != 0) {
    throw failed(errno);
  }
  if (::connect(socket.fd(), reinterpret_cast<const sockaddr*>(&to), sizeof to) == 0) return;
  if (errno != EINTR) throw failed(errno);
  // Interrupted by a signal, the connection goes on in the background.
  if (!ready_before(socket, POLLOUT, deadline)) throw failed(ETIMEDOUT);
  int error = 0;
  socklen_t length = sizeof error;
  ::getsockopt(socket.fd(), SOL_SOCKET, SO_ERROR, &error, &length);
  if (error != 0) throw failed(error);
}

// The server may close the connection before it has read everything (bytes that are
// not Modbus TCP): a failed send is the client's loss, not a bug.
void send_all(const Socket& socket, std::span<const std::uint8_t> bytes) {
  for (std::size_t sent = 0; sent < bytes.size();) {
    const ssize_t n = ::send(socket.fd(), bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n == -1 && errno == EINTR) continue;
    if (n <= 0) return;
    sent += static_cast<std::size_t>(n);
  }
}

unsigned tcp_state(const Socket& socket) {
  tcp_info info{};
  socklen_t length = sizeof info;
  ::getsockopt(socket.fd(), IPPROTO_TCP, TCP_INFO, &info, &length);
  return info.tcpi_state;
}

// How long this process's threads have waited for a CPU while ready to run, in all
// (/proc/self/task/*/schedstat, second field): the time a loaded machine took from them.
std::chrono::nanoseconds run_delay() {
  std::uint64_t total = 0;
  std::error_code error;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", error)) {
    std::ifstream schedstat(task.path() / "schedstat");
    std::uint64_t running = 0;
    std::uint64_t waiting = 0;
    if (schedstat >> running >> waiting) total += waiting;
  }
  return std::chrono::nanoseconds(total);
}

// Whether a thread of this process other than the caller is ready to run but waiting for a
// CPU: schedstat counts that wait only once the thread gets one.
bool another_thread_waits_for_a_cpu() {
  const auto self = std::to_string(::gettid());
  std::error_code error;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", error)) {
    if (task.path().filename() == self) continue;
    std::ifstream stat(task.path() / "stat");
    std::string line;
    std::getline(stat, line);
    // "tid (name) S ...": the state follows the name, which may hold spaces and ')'.
    const auto name_end = line.rfind(')');
    if (name_end != std::string::npos && name_end + 2 < line.size() && line[name_end + 2] == 'R') {
      return true;
    }
  }
  return false;
}

}  // namespace

LoopbackModbusServer::LoopbackModbusServer(modbus::ServerOptions options) {
  options.address = "127.0.0.1";
  for (int attempt = 0; attempt < 5 && !server_; ++attempt) {
    options.port = free_loopback_port();
    try {
      server_ = std::make_unique<modbus::ModbusServer>(options, latest_, Logger("modbus"));
      port_ = options.port;
    } catch (const Error&) {  // the port was taken in between: another one
    }
  }
  if (!server_) throw Error("cannot start the Modbus server on a free loopback port (5 tries)");
}

HalfCloseOutcome half_close_session(std::uint32_t source, int port,
                                    std::span<const std::uint8_t> request,
                                    std::chrono::milliseconds timeout,
                                    std::size_t max_reply_bytes) {
  const Socket socket;
  connect_from(socket, source, port, Clock::now() + timeout);
  send_all(socket, request);
  ::shutdown(socket.fd(), SHUT_WR);

  const auto half_closed = Clock::now();
  const auto delayed_before = run_delay();
  // The timeout counts the server's time, not the time a loaded machine kept this process
  // waiting for a CPU: the deadline moves on by that, and past it while a server thread
  // is still waiting for one.
  const auto readable = [&] {
    constexpr std::chrono::milliseconds kWaitingForACpu{10};
    for (;;) {
      const auto starved = std::max(run_delay() - delayed_before, std::chrono::nanoseconds(0));
      auto deadline = half_closed + timeout + std::chrono::duration_cast<Clock::duration>(starved);
      if (Clock::now() >= deadline) {
        if (!another_thread_waits_for_a_cpu()) return false;
        deadline = Clock::now() + kWaitingForACpu;
      }
      if (ready_before(socket, POLLIN, deadline)) return true;
    }
  };
  HalfCloseOutcome outcome;
  while (outcome.replies.size() <= max_reply_bytes) {
    if (!readable()) {
      outcome.tcp_state = tcp_state(socket);
      break;
    }
    std::uint8_t buffer[4096];
    const ssize_t n = ::recv(socket.fd(), buffer, sizeof buffer, 0);
    if (n == -1 && errno == EINTR) continue;
    if (n <= 0) {  // closed (or reset after the bytes it refused)
      outcome.closed = true;
      break;
    }
    outcome.replies.insert(outcome.replies.end(), buffer, buffer + n);
  }
  outcome.waited =
      std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - half_closed);
  return outcome;
}

}  // namespace tilth::fuzz
