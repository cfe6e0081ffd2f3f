// Modbus TCP client mode: Tilth writes the register block into the PLC's holding
// registers at a fixed rate from a thread of its own, and reconnects after the PLC goes
// away.
#pragma once

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <modbus.h>

#include "latest_measurement.h"
#include "register_map.h"
#include "tilth/log.h"

namespace tilth::modbus {

struct ClientOptions {
  std::string address;  // the PLC's IPv4 address
  int port = 502;
  int unit_id = 1;
  int base_register = 0;
  WordOrder word_order = WordOrder::kHighFirst;
  std::chrono::milliseconds write_interval{40};
};

class ModbusClient {
 public:
  // Starts the writing thread; connecting happens there, so a PLC that is not up yet
  // does not stop the graph. Throws tilth::Error when libmodbus refuses the address.
  ModbusClient(const ClientOptions& options, const LatestMeasurement& latest, Logger log);
  // Stops the thread (at most one response timeout later) and closes the connection.
  ~ModbusClient();
  ModbusClient(const ModbusClient&) = delete;
  ModbusClient& operator=(const ModbusClient&) = delete;

 private:
  struct ContextDeleter {
    void operator()(modbus_t* context) const;
  };

  void run();
  // Waits until `deadline` or stop; false when stopping.
  bool wait_until(std::chrono::steady_clock::time_point deadline);

  const ClientOptions options_;
  const LatestMeasurement& latest_;
  const Logger log_;
  const std::unique_ptr<modbus_t, ContextDeleter> context_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace tilth::modbus
