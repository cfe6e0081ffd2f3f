// Modbus TCP server mode: Tilth listens, PLCs poll the register block. One thread of its
// own serves every connection; the graph only updates the LatestMeasurement it reads.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

#include "ipv4_ranges.h"
#include "latest_measurement.h"
#include "register_map.h"
#include "tilth/log.h"

namespace tilth::modbus {

struct ServerOptions {
  std::string address;  // IPv4 address to listen on; 0.0.0.0 = every interface
  int port = 502;
  int unit_id = 1;
  int base_register = 0;
  WordOrder word_order = WordOrder::kHighFirst;
  // Who may connect (docs/modbus.md, "Connections"). The PLC's connections have slots
  // of their own and are never closed to make room or for being idle; other clients
  // share max_clients slots, are refused when those are taken, and are closed after
  // idle_timeout without a request (zero: never).
  Ipv4Ranges plc;
  int plc_clients = 2;
  Ipv4Ranges allow;  // empty: every address; the PLC's are always allowed
  int max_clients = 8;
  std::chrono::milliseconds idle_timeout{5000};
};

class ModbusServer {
 public:
  // Listens before returning; throws tilth::Error naming the address when it cannot.
  ModbusServer(const ServerOptions& options, const LatestMeasurement& latest, Logger log);
  // Stops the thread and closes every socket.
  ~ModbusServer();
  ModbusServer(const ModbusServer&) = delete;
  ModbusServer& operator=(const ModbusServer&) = delete;

 private:
  class Connections;

  std::unique_ptr<Connections> connections_;
  int wake_fd_ = -1;  // an eventfd: written to stop the thread at once
  std::thread thread_;
};

}  // namespace tilth::modbus
