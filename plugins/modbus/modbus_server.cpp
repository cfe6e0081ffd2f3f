// The server thread: poll() over the listening socket, every connection and a wake-up
// eventfd, and never a blocking call on one connection.
//
//   PLC A ──┐
//   PLC B ──┼─ poll() ─ whole frame collected? ─ checked ─ modbus_reply(): registers
//   tool  ──┘                                          └─ modbus_reply_exception()
//
// Invariant: one client cannot delay or disturb another. Each connection's bytes are
// collected until a whole Modbus TCP frame (MBAP header + PDU) is there, and only then
// answered. libmodbus's modbus_receive() is not used for this: after the first bytes of
// a frame it waits up to byte_timeout for the rest, so a client that sends half a
// request would hold up every other one. Requests are checked here before libmodbus sees
// them, because modbus_reply() sleeps response_timeout and flushes the socket on a bad
// register count, and would write into the mapping. A client that sends something that
// is not Modbus TCP is disconnected; a well-formed request it may not make gets the
// exception docs/modbus.md lists, and the connection stays open.
//
// The mapping belongs to this thread alone; only the LatestMeasurement it reads from is
// shared with the graph (under that object's mutex).
#include "modbus_server.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
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

#include "tilth/error.h"

namespace tilth::modbus {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::size_t kMbapSize = 7;             // transaction, protocol, length, unit
constexpr std::size_t kMaxLengthField = 254;     // unit id + the largest PDU (253 bytes)
constexpr std::uint8_t kThisDeviceUnit = 0xFF;   // Modbus TCP: "the device itself"
constexpr std::uint8_t kUnaddressedUnit = 0x00;  // what many TCP masters send by default
constexpr std::chrono::milliseconds kHeartbeatPeriod{10};

std::uint16_t word_at(std::span<const std::uint8_t> bytes, std::size_t offset) {
  return static_cast<std::uint16_t>(bytes[offset] << 8 | bytes[offset + 1]);
}

std::string peer_name(const sockaddr_in& address) {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &address.sin_addr, text, sizeof text);
  return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

struct Connection {
  int fd = -1;
  std::string peer;
  std::vector<std::uint8_t> pending;  // bytes of a frame not yet complete
  Clock::time_point last_request;     // the time of connecting until the first request
  bool warned = false;  // the first refused request is a warning, later ones debug lines
};

}  // namespace

class ModbusServer::Connections {
 public:
  Connections(const ServerOptions& options, const LatestMeasurement& latest, Logger log)
      : options_(options), latest_(latest), log_(std::move(log)), started_(Clock::now()) {
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
    listen_fd_ = modbus_tcp_listen(context_, options.max_clients);
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
              std::to_string(base + kRegisterCount - 1));
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
      if (::poll(polled.data(), polled.size(), -1) == -1) {
        if (errno == EINTR) continue;
        log_.error(std::string("Modbus server stopped: poll failed: ") + std::strerror(errno));
        return;
      }
      if (polled[0].revents != 0) return;
      for (std::size_t i = 0; i < connections_.size(); ++i) {
        if (polled[i + 2].revents != 0) receive(connections_[i]);
      }
      std::erase_if(connections_, [](const Connection& c) { return c.fd == -1; });
      if (polled[1].revents != 0) accept_connection();
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

  void accept_connection() {
    sockaddr_in address{};
    socklen_t length = sizeof address;
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&address), &length,
                             SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd == -1) {
      const int error = errno;
      if (error != EAGAIN && error != EWOULDBLOCK && error != ECONNABORTED && error != EINTR) {
        log_.error(std::string("cannot accept a connection: ") + std::strerror(error));
      }
      return;
    }
    const int on = 1;
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);  // answers are single packets
    Connection connection{fd, peer_name(address), {}, Clock::now(), false};
    if (connections_.size() >= static_cast<std::size_t>(options_.max_clients)) {
      // A PLC that lost its link reconnects while its old connection still looks open:
      // make room by dropping the connection that has been quiet longest.
      auto quietest = std::min_element(
          connections_.begin(), connections_.end(),
          [](const Connection& a, const Connection& b) { return a.last_request < b.last_request; });
      log_.warning("max_clients (" + std::to_string(options_.max_clients) +
                   ") reached: closing the quietest connection, from " + quietest->peer +
                   ", to accept " + connection.peer);
      ::close(quietest->fd);
      connections_.erase(quietest);
    }
    log_.info("Modbus client connected from " + connection.peer);
    connections_.push_back(std::move(connection));
  }

  // Reads what the socket has and answers every whole frame; closes the connection on
  // end of stream, on an error, or when the bytes are not Modbus TCP.
  void receive(Connection& connection) {
    std::array<std::uint8_t, 512> buffer;
    const ssize_t received = ::recv(connection.fd, buffer.data(), buffer.size(), 0);
    if (received == 0) return close(connection, LogLevel::kInfo, "disconnected");
    if (received < 0) {
      const int error = errno;
      if (error == EAGAIN || error == EWOULDBLOCK || error == EINTR) return;
      return close(connection, LogLevel::kWarning,
                   std::string("receive failed: ") + std::strerror(error));
    }
    auto& pending = connection.pending;
    pending.insert(pending.end(), buffer.begin(), buffer.begin() + received);
    while (pending.size() >= kMbapSize) {
      const std::uint16_t protocol = word_at(pending, 2);
      const std::uint16_t length = word_at(pending, 4);
      if (protocol != 0 || length < 2 || length > kMaxLengthField) {
        return close(connection, LogLevel::kWarning,
                     "sent bytes that are not Modbus TCP (protocol id " + std::to_string(protocol) +
                         ", length " + std::to_string(length) + "); disconnected");
      }
      const std::size_t frame_size = 6 + length;
      if (pending.size() < frame_size) return;
      if (pending[kMbapSize] >= 0x80) {
        return close(connection, LogLevel::kWarning,
                     "sent function code " + std::to_string(pending[kMbapSize]) +
                         ", which is not a request; disconnected");
      }
      if (!answer(connection, std::span<const std::uint8_t>(pending.data(), frame_size))) {
        const int error = errno;
        return close(connection, LogLevel::kWarning,
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

  void close(Connection& connection, LogLevel level, const std::string& why) {
    log(level, log_.where(), "Modbus client " + connection.peer + " " + why);
    ::close(connection.fd);
    connection.fd = -1;
  }

  const ServerOptions options_;
  const LatestMeasurement& latest_;
  const Logger log_;
  const Clock::time_point started_;
  modbus_t* context_ = nullptr;
  modbus_mapping_t* mapping_ = nullptr;
  int listen_fd_ = -1;
  std::vector<Connection> connections_;
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
