// Modbus TCP server mode: Tilth listens, PLCs poll the register block. One thread of its
// own serves every connection; the graph only updates the LatestMeasurement it reads.
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>

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
  int max_clients = 8;
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
