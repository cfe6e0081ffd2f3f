// The Modbus server on a free loopback port, and one client connection to it as the
// modbus_request fuzz target makes them; shared with tests/modbus, which check the
// target's verdicts as well as the server.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "latest_measurement.h"
#include "modbus_server.h"

namespace tilth::fuzz {

// A ModbusServer on 127.0.0.1 and a port nothing listened on when it started.
class LoopbackModbusServer {
 public:
  // `options` without address and port; throws tilth::Error when no port is found.
  explicit LoopbackModbusServer(modbus::ServerOptions options);
  // The server reads latest_ by reference.
  LoopbackModbusServer(const LoopbackModbusServer&) = delete;
  LoopbackModbusServer& operator=(const LoopbackModbusServer&) = delete;
  int port() const { return port_; }

 private:
  modbus::LatestMeasurement latest_{std::chrono::milliseconds(500)};
  int port_ = 0;
  std::unique_ptr<modbus::ModbusServer> server_;
};

struct HalfCloseOutcome {
  std::vector<std::uint8_t> replies;   // every byte the server sent, up to the limit
  bool closed = false;                 // the server closed the connection (FIN or RST)
  unsigned tcp_state = 0;              // the client's TCP state (tcp_info) when not closed
  std::chrono::milliseconds waited{};  // from the half-close to the close or the deadline
};

// Connects from `source` (an IPv4 loopback address, host byte order) to the server on
// 127.0.0.1:`port`, sends `request`, closes its sending side and reads every reply until
// the server closes, `timeout` has passed since the half-close (not counting the time this
// process waited for a CPU on a loaded machine), or more than `max_reply_bytes` arrived. Signals
// (libFuzzer's SIGALRM) interrupt none of the waits. Throws tilth::Error when it cannot connect
// within `timeout`.
HalfCloseOutcome half_close_session(std::uint32_t source, int port,
                                    std::span<const std::uint8_t> request,
                                    std::chrono::milliseconds timeout, std::size_t max_reply_bytes);

}  // namespace tilth::fuzz
