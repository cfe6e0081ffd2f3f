// The server thread: poll() over the listening socket, every connection and a wake-up
// eventfd, and never a blocking call on one connection.
//
//   PLC ──────┐  (plc_address: slots of its own, never closed for others)
//   HMI ──────┼─ poll() ─ whole frame collected? ─ checked ─ modbus_reply(): registers
//   laptop ───┘  (max_clients slots)                    └─ modbus_reply_exception()
//
// Invariant: no other client can disconnect the PLC or hold up its answers. Each
// connection's bytes are collected until a whole Modbus TCP frame (MBAP header + PDU)
// is there, and only then answered. libmodbus's modbus_receive() is not used for this:
// it waits without a timeout for a request's first bytes and then up to byte_timeout
// for each further chunk, so a silent client or one that sends half a request would
// hold up every other one. Requests are checked here before libmodbus sees them,
// because modbus_reply() sleeps response_timeout and flushes the socket on a bad
// register count, and would write into the mapping. A client that sends something that
// is not Modbus TCP is disconnected; a well-formed request it may not make gets the
// exception docs/modbus.md lists, and the connection stays open.
//
// A new connection from outside `allow`, or from another client while max_clients are
// connected, is closed at once: an active client is never evicted for a newcomer, and
// idle ones leave by idle_timeout. Events that may come in floods (refusals, idle
// closes, other clients' connects and protocol errors) are logged through LogThrottles.
//
// The mapping belongs to this thread alone; only the LatestMeasurement it reads from is
// shared with the graph (under that object's mutex).
#include "modbus_server.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <optional>
#include <span>
#include <vector>

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include "log_throttle.h"
#include "tilth/error.h"

namespace tilth::modbus {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr std::size_t kMbapSize = 7;             // transaction, protocol, length, unit
constexpr std::size_t kMaxLengthField = 254;     // unit id + the largest PDU (253 bytes)
constexpr std::uint8_t kThisDeviceUnit = 0xFF;   // Modbus TCP: "the device itself"
constexpr std::uint8_t kUnaddressedUnit = 0x00;  // what many TCP masters send by default
constexpr milliseconds kHeartbeatPeriod{10};
// A burst of connections waits in the kernel instead of being dropped before accept()
// sees it (the kernel caps this at net.core.somaxconn).
constexpr int kListenBacklog = SOMAXCONN;
// Connections accepted per wake-up, so a flood of them cannot starve the PLC's requests.
constexpr int kAcceptsPerWake = 64;
// At most one line per this period for each kind of event that may come in floods.
constexpr milliseconds kLogPeriod{10000};
// TCP keepalive on the PLC's connections, which are never closed for being idle: a PLC
// that vanished (power cut, cable pulled) is noticed some 5 s after its last request.
constexpr int kKeepaliveIdleS = 2;
constexpr int kKeepaliveIntervalS = 1;
constexpr int kKeepaliveProbes = 3;

std::uint16_t word_at(std::span<const std::uint8_t> bytes, std::size_t offset) {
  return static_cast<std::uint16_t>(bytes[offset] << 8 | bytes[offset + 1]);
}

std::string peer_name(const sockaddr_in& address) {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

std::string ms_text(Clock::duration duration) {
  return std::to_string(std::chrono::duration_cast<milliseconds>(duration).count()) + " ms";
}

void keep_alive(int fd) {
  const int on = 1;
  setsockopt(fd, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on);
  setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &kKeepaliveIdleS, sizeof kKeepaliveIdleS);
  setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &kKeepaliveIntervalS, sizeof kKeepaliveIntervalS);
  setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &kKeepaliveProbes, sizeof kKeepaliveProbes);
}

struct Connection {
  int fd = -1;
  std::string peer;
  bool plc = false;
  std::vector<std::uint8_t> pending;  // bytes of a frame not yet complete
  Clock::time_point last_request;     // the time of connecting until the first request
  bool warned = false;  // the first refused request is a warning, later ones debug lines
};

// Why a connection ends, which decides how it is logged.
enum class Ending { kLeft, kFailed, kNotModbus, kIdle };

}  // namespace

class ModbusServer::Connections {
 public:
  Connections(const ServerOptions& options, const LatestMeasurement& latest, Logger log)
      : options_(options),
        latest_(latest),
        log_(std::move(log)),
        started_(Clock::now()),
        comings_and_goings_(log_, LogLevel::kInfo, kLogPeriod),
        refused_outsiders_(log_, LogLevel::kWarning, kLogPeriod),
        refused_when_full_(log_, LogLevel::kWarning, kLogPeriod),
        idle_closes_(log_, LogLevel::kInfo, kLogPeriod),
        protocol_errors_(log_, LogLevel::kWarning, kLogPeriod) {
    const std::string where = options.address + ":" + std::to_string(options.port);
    context_ = modbus_new_tcp(options.address.c_str(), options.port);
    if (context_ == nullptr) {
      throw Error("address '" + options.address + "': " + modbus_strerror(errno));
    }
    const auto base = static_cast<unsigned>(options.base_register);
    mapping_ =
        modbus_mapping_new_start_address(0, 0, 0, 0, base, kRegisterCount, base, kRegisterCount);
    if (mapping_ == nullptr) {
      release();
      throw Error("cannot allocate the register mapping");
    }
    listen_fd_ = modbus_tcp_listen(context_, kListenBacklog);
    if (listen_fd_ == -1) {
      const int error = errno;
      release();
      throw Error("cannot listen on " + where + ": " + modbus_strerror(error) +
                  " (expected a local address and a free port)");
    }
    // A connection reset between poll() and accept() must not block the thread.
    ::fcntl(listen_fd_, F_SETFL, ::fcntl(listen_fd_, F_GETFL) | O_NONBLOCK);
    log_.info("Modbus TCP server listening on " + where + ", unit " +
              std::to_string(options.unit_id) + ", registers " + std::to_string(base) + ".." +
              std::to_string(base + kRegisterCount - 1) + "; " + policy_text());
  }

  ~Connections() {
    for (auto& connection : connections_) ::close(connection.fd);
    release();
  }

  Connections(const Connections&) = delete;
  Connections& operator=(const Connections&) = delete;

  // Serves until `wake_fd` becomes readable.
  void serve(int wake_fd) {
    std::vector<pollfd> polled;
    for (;;) {
      polled.assign({{wake_fd, POLLIN, 0}, {listen_fd_, POLLIN, 0}});
      for (const auto& connection : connections_) polled.push_back({connection.fd, POLLIN, 0});
      if (::poll(polled.data(), polled.size(), poll_timeout_ms(Clock::now())) == -1) {
        if (errno == EINTR) continue;
        log_.error(std::string("Modbus server stopped: poll failed: ") + std::strerror(errno));
        return;
      }
      if (polled[0].revents != 0) {
        for (LogThrottle* throttle : throttles()) throttle->summarize(Clock::now());
        return;
      }
      for (std::size_t i = 0; i < connections_.size(); ++i) {
        if (polled[i + 2].revents != 0) receive(connections_[i]);
      }
      const auto now = Clock::now();
      close_idle(now);
      std::erase_if(connections_, [](const Connection& c) { return c.fd == -1; });
      if (polled[1].revents != 0) accept_connections(now);
      for (LogThrottle* throttle : throttles()) throttle->flush(now);
    }
  }

 private:
  void release() {
    if (listen_fd_ != -1) ::close(listen_fd_);
    if (mapping_ != nullptr) modbus_mapping_free(mapping_);
    // The context only ever borrowed the connections' sockets.
    modbus_set_socket(context_, -1);
    modbus_free(context_);
  }

  std::string policy_text() const {
    std::string text = "PLC " + (options_.plc.empty()
                                     ? std::string("addresses: none")
                                     : options_.plc.text() + " (" +
                                           std::to_string(options_.plc_clients) + " connections)");
    text += ", other clients: " + std::to_string(options_.max_clients);
    if (!options_.allow.empty()) text += " from " + options_.allow.text();
    text +=
        ", idle timeout " +
        (options_.idle_timeout.count() == 0 ? std::string("none") : ms_text(options_.idle_timeout));
    return text;
  }

  std::array<LogThrottle*, 5> throttles() {
    return {&comings_and_goings_, &refused_outsiders_, &refused_when_full_, &idle_closes_,
            &protocol_errors_};
  }

  bool idle_timeout_applies(const Connection& connection) const {
    return !connection.plc && options_.idle_timeout.count() > 0;
  }

  // Until the next idle timeout or log summary is due; -1 (forever) when none is.
  int poll_timeout_ms(Clock::time_point now) {
    std::optional<Clock::time_point> next;
    const auto earlier = [&next](Clock::time_point at) { next = next ? std::min(*next, at) : at; };
    for (const auto& connection : connections_) {
      if (idle_timeout_applies(connection))
        earlier(connection.last_request + options_.idle_timeout);
    }
    for (LogThrottle* throttle : throttles()) {
      if (const auto deadline = throttle->deadline()) earlier(*deadline);
    }
    if (!next) return -1;
    // Rounded up, so that the deadline has passed when poll() returns.
    const auto wait = std::chrono::ceil<milliseconds>(*next - now).count();
    return static_cast<int>(std::clamp<std::int64_t>(wait, 0, 60000));
  }

  void close_idle(Clock::time_point now) {
    for (auto& connection : connections_) {
      if (connection.fd != -1 && idle_timeout_applies(connection) &&
          now - connection.last_request >= options_.idle_timeout) {
        close(connection, Ending::kIdle,
              "closed: no request for " + ms_text(now - connection.last_request) +
                  " (idle_timeout_ms " + std::to_string(options_.idle_timeout.count()) + ")");
      }
    }
  }

  void accept_connections(Clock::time_point now) {
    for (int i = 0; i < kAcceptsPerWake; ++i) {
      sockaddr_in address{};
      socklen_t length = sizeof address;
      const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length,
                               SOCK_NONBLOCK | SOCK_CLOEXEC);
      if (fd == -1) {
        const int error = errno;
        if (error == ECONNABORTED || error == EINTR) continue;
        if (error != EAGAIN && error != EWOULDBLOCK) {
          log_.error(std::string("cannot accept a connection: ") + std::strerror(error));
        }
        return;
      }
      const std::uint32_t peer_address = ntohl(address.sin_addr.s_addr);
      admit(Connection{fd, peer_name(address), options_.plc.contains(peer_address), {}, now, false},
            peer_address, now);
    }
  }

  // Keeps `connection`, or closes it at once with the reason logged.
  void admit(Connection connection, std::uint32_t address, Clock::time_point now) {
    if (!connection.plc && !options_.allow.empty() && !options_.allow.contains(address)) {
      return refuse(connection, refused_outsiders_, now,
                    "not in 'allow' (" + options_.allow.text() + ")");
    }
    const int slots = connection.plc ? options_.plc_clients : options_.max_clients;
    // A client that reconnects at once must find the slot of its old connection free,
    // also when that connection's end arrived after poll() returned.
    if (taken(connection.plc) >= slots) serve_ready_connections();
    if (connection.plc) {
      if (taken(true) >= slots) make_room_for_plc(connection, now);
      keep_alive(connection.fd);
    } else if (taken(false) >= slots) {
      return refuse(connection, refused_when_full_, now,
                    "max_clients (" + std::to_string(slots) + ") other clients are connected");
    }
    const int on = 1;
    setsockopt(connection.fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);  // one packet each
    const std::string what = "Modbus client connected from " + connection.peer;
    if (connection.plc) {
      log_.info(what + " (PLC)");
    } else {
      comings_and_goings_.event(now, what);
    }
    connections_.push_back(std::move(connection));
  }

  // The PLC's connections, or the other clients'.
  int taken(bool plc) const {
    return static_cast<int>(std::count_if(connections_.begin(), connections_.end(),
                                          [plc](const Connection& c) { return c.plc == plc; }));
  }

  // Reads and answers what has arrived on any connection by now, without waiting.
  void serve_ready_connections() {
    std::vector<pollfd> polled;
    for (const auto& connection : connections_) polled.push_back({connection.fd, POLLIN, 0});
    if (::poll(polled.data(), polled.size(), 0) <= 0) return;
    for (std::size_t i = 0; i < connections_.size(); ++i) {
      if (polled[i].revents != 0) receive(connections_[i]);
    }
    std::erase_if(connections_, [](const Connection& c) { return c.fd == -1; });
  }

  // A PLC that lost its link reconnects while its old connection still looks open: the
  // PLC connection quiet longest makes room (keepalive would only close it seconds later).
  void make_room_for_plc(const Connection& newcomer, Clock::time_point now) {
    auto quietest = connections_.end();
    for (auto it = connections_.begin(); it != connections_.end(); ++it) {
      if (it->plc &&
          (quietest == connections_.end() || it->last_request < quietest->last_request)) {
        quietest = it;
      }
    }
    log_.warning("plc_clients (" + std::to_string(options_.plc_clients) +
                 ") PLC connections open: closing the one from " + quietest->peer + ", quiet for " +
                 ms_text(now - quietest->last_request) + ", to accept " + newcomer.peer);
    ::close(quietest->fd);
    connections_.erase(quietest);
  }

  void refuse(Connection& connection, LogThrottle& throttle, Clock::time_point now,
              const std::string& why) {
    ::close(connection.fd);
    throttle.event(now, "refused the connection from " + connection.peer + ": " + why);
  }

  // Reads what the socket has and answers every whole frame; closes the connection on
  // end of stream, on an error, or when the bytes are not Modbus TCP.
  void receive(Connection& connection) {
    std::array<std::uint8_t, 512> buffer;
    const ssize_t received = ::recv(connection.fd, buffer.data(), buffer.size(), 0);
    if (received == 0) return close(connection, Ending::kLeft, "disconnected");
    if (received < 0) {
      const int error = errno;
      if (error == EAGAIN || error == EWOULDBLOCK || error == EINTR) return;
      return close(connection, Ending::kFailed,
                   std::string("receive failed: ") + std::strerror(error));
    }
    auto& pending = connection.pending;
    pending.insert(pending.end(), buffer.begin(), buffer.begin() + received);
    while (pending.size() >= kMbapSize) {
      const std::uint16_t protocol = word_at(pending, 2);
      const std::uint16_t length = word_at(pending, 4);
      if (protocol != 0 || length < 2 || length > kMaxLengthField) {
        return close(connection, Ending::kNotModbus,
                     "sent bytes that are not Modbus TCP (protocol id " + std::to_string(protocol) +
                         ", length " + std::to_string(length) +
                         "; expected protocol id 0 and length 2.." +
                         std::to_string(kMaxLengthField) + "); disconnected");
      }
      const std::size_t frame_size = 6 + length;
      if (pending.size() < frame_size) return;
      if (pending[kMbapSize] >= 0x80) {
        return close(connection, Ending::kNotModbus,
                     "sent function code " + std::to_string(pending[kMbapSize]) +
                         ", which is not a request; disconnected");
      }
      if (!answer(connection, std::span<const std::uint8_t>(pending.data(), frame_size))) {
        const int error = errno;
        return close(connection, Ending::kFailed,
                     std::string("send failed: ") + modbus_strerror(error));
      }
      pending.erase(pending.begin(), pending.begin() + static_cast<std::ptrdiff_t>(frame_size));
    }
  }
  // The exception code a well-formed frame gets, or 0 when it is a read to serve.
  int check(std::span<const std::uint8_t> frame) const {
    const std::uint8_t unit = frame[kMbapSize - 1];
    if (unit != options_.unit_id && unit != kThisDeviceUnit && unit != kUnaddressedUnit) {
      return MODBUS_EXCEPTION_GATEWAY_TARGET;
    }
    const auto pdu = frame.subspan(kMbapSize);
    switch (pdu[0]) {
      case MODBUS_FC_READ_HOLDING_REGISTERS:
      case MODBUS_FC_READ_INPUT_REGISTERS: {
        if (pdu.size() != 5) return MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
        const int first = word_at(pdu, 1);
        const int count = word_at(pdu, 3);
        if (count < 1 || count > MODBUS_MAX_READ_REGISTERS) {
          return MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE;
        }
        if (first < options_.base_register ||
            first + count > options_.base_register + static_cast<int>(kRegisterCount)) {
          return MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS;
        }
        return 0;
      }
      case MODBUS_FC_WRITE_SINGLE_REGISTER:
      case MODBUS_FC_WRITE_MULTIPLE_REGISTERS:
      case MODBUS_FC_MASK_WRITE_REGISTER:
      case MODBUS_FC_WRITE_AND_READ_REGISTERS:
        return MODBUS_EXCEPTION_ILLEGAL_DATA_ADDRESS;  // every register is read-only
      default:
        return MODBUS_EXCEPTION_ILLEGAL_FUNCTION;
    }
  }

  // False when the answer could not be sent.
  bool answer(Connection& connection, std::span<const std::uint8_t> frame) {
    const auto now = Clock::now();
    connection.last_request = now;
    modbus_set_socket(context_, connection.fd);
    if (const int exception = check(frame)) {
      const std::string what = "refused function " + std::to_string(frame[kMbapSize]) + " from " +
                               connection.peer + " (unit " + std::to_string(frame[kMbapSize - 1]) +
                               "): exception " + std::to_string(exception);
      if (connection.warned) {
        log_.debug(what);
      } else {
        log_.warning(what + " (further ones from this client: debug log)");
        connection.warned = true;
      }
      return modbus_reply_exception(context_, frame.data(), static_cast<unsigned>(exception)) != -1;
    }
    RegisterValues values = latest_.values_at(now);
    values.heartbeat = static_cast<std::uint16_t>((now - started_) / kHeartbeatPeriod);
    const RegisterBlock block = encode(values, options_.word_order);
    std::copy(block.begin(), block.end(), mapping_->tab_registers);
    std::copy(block.begin(), block.end(), mapping_->tab_input_registers);
    return modbus_reply(context_, frame.data(), static_cast<int>(frame.size()), mapping_) != -1;
  }

  // The PLC's connection ends are logged each; other clients' through the throttles.
  void close(Connection& connection, Ending ending, const std::string& why) {
    ::close(connection.fd);
    connection.fd = -1;
    const auto now = Clock::now();
    if (connection.plc) {
      const LogLevel level = ending == Ending::kLeft ? LogLevel::kInfo : LogLevel::kWarning;
      return log(level, log_.where(), "Modbus client " + connection.peer + " (PLC) " + why);
    }
    const std::string what = "Modbus client " + connection.peer + " " + why;
    switch (ending) {
      case Ending::kLeft:
      case Ending::kFailed:
        return comings_and_goings_.event(now, what);
      case Ending::kNotModbus:
        return protocol_errors_.event(now, what);
      case Ending::kIdle:
        return idle_closes_.event(now, what);
    }
  }

  const ServerOptions options_;
  const LatestMeasurement& latest_;
  const Logger log_;
  const Clock::time_point started_;
  modbus_t* context_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  int listen_fd_ = -1;
  std::vector<Connection> connections_;
  LogThrottle comings_and_goings_;
  LogThrottle refused_outsiders_;
  LogThrottle refused_when_full_;
  LogThrottle idle_closes_;
  LogThrottle protocol_errors_;
};

ModbusServer::ModbusServer(const ServerOptions& options, const LatestMeasurement& latest,
                           Logger log)
    : connections_(std::make_unique<Connections>(options, latest, std::move(log))) {
  wake_fd_ = ::eventfd(0, EFD_CLOEXEC);
  if (wake_fd_ == -1) throw Error(std::string("cannot create an eventfd: ") + std::strerror(errno));
  thread_ = std::thread([this] { connections_->serve(wake_fd_); });
}

ModbusServer::~ModbusServer() {
  eventfd_write(wake_fd_, 1);  // cannot fail: the counter is nowhere near overflowing
  thread_.join();
  ::close(wake_fd_);
}

}  // namespace tilth::modbus
