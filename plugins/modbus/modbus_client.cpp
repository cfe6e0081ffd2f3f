// The writing loop: connect, write the block every write_interval, and when the
// connection is lost close it and try again after 0.1 s, doubling up to 2 s, so a PLC
// that restarts is written to again at most 2 s after it is back.
//
// Connection changes are logged once each (connected, lost, cannot connect), not per
// attempt. An exception response (a register outside the PLC's area, say) keeps the
// connection: it is logged once and the writes go on.
#include "modbus_client.h"

#include <algorithm>
#include <cerrno>

#include "tilth/error.h"

namespace tilth::modbus {
namespace {

using Clock = std::chrono::steady_clock;

constexpr std::chrono::milliseconds kFirstRetry{100};
constexpr std::chrono::milliseconds kLongestRetry{2000};
constexpr std::uint32_t kResponseTimeoutUs = 500'000;  // for connecting and for each write

bool is_exception_response(int error) {
  return error > MODBUS_ENOBASE && error < MODBUS_ENOBASE + MODBUS_EXCEPTION_MAX;
}

}  // namespace

void ModbusClient::ContextDeleter::operator()(modbus_t* context) const {
  modbus_close(context);
  modbus_free(context);
}

ModbusClient::ModbusClient(const ClientOptions& options, const LatestMeasurement& latest,
                           Logger log)
    : options_(options),
      latest_(latest),
      log_(std::move(log)),
      context_(modbus_new_tcp(options.address.c_str(), options.port)) {
  if (!context_) throw Error("address '" + options.address + "': " + modbus_strerror(errno));
  modbus_set_slave(context_.get(), options.unit_id);
  modbus_set_response_timeout(context_.get(), 0, kResponseTimeoutUs);
  thread_ = std::thread([this] { run(); });
}

ModbusClient::~ModbusClient() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

bool ModbusClient::wait_until(Clock::time_point deadline) {
  std::unique_lock lock(mutex_);
  return !wake_.wait_until(lock, deadline, [this] { return stopping_; });
}

void ModbusClient::run() {
  modbus_t* context = context_.get();
  const std::string plc = options_.address + ":" + std::to_string(options_.port);
  const std::string registers = std::to_string(options_.base_register) + ".." +
                                std::to_string(options_.base_register + kRegisterCount - 1);
  auto retry = kFirstRetry;
  bool connected = false;
  bool connect_failure_logged = false;
  int last_refusal = 0;  // the exception of the last refused write, logged once
  std::uint16_t heartbeat = 0;
  auto next_write = Clock::now();
  for (;;) {
    if (!connected) {
      if (modbus_connect(context) == -1) {
        const int error = errno;
        if (!connect_failure_logged) {
          log_.warning("cannot connect to the PLC at " + plc + ": " + modbus_strerror(error) +
                       "; retrying");
          connect_failure_logged = true;
        }
        if (!wait_until(Clock::now() + retry)) return;
        retry = std::min(retry * 2, kLongestRetry);
        continue;
      }
      log_.info("connected to the PLC at " + plc + "; writing registers " + registers);
      connected = true;
      connect_failure_logged = false;
      retry = kFirstRetry;
      next_write = Clock::now();
    }
    RegisterValues values = latest_.values_at(Clock::now());
    values.heartbeat = heartbeat;
    const RegisterBlock block = encode(values, options_.word_order);
    const int written =
        modbus_write_registers(context, options_.base_register, kRegisterCount, block.data());
    const int error = errno;
    if (written == static_cast<int>(kRegisterCount)) {
      ++heartbeat;
      last_refusal = 0;
    } else if (is_exception_response(error)) {
      if (error != last_refusal) {
        log_.warning("the PLC at " + plc + " refused the write to registers " + registers + ": " +
                     modbus_strerror(error) + "; writing on");
        last_refusal = error;
      }
    } else {
      log_.warning("connection to the PLC at " + plc + " lost: " + modbus_strerror(error) +
                   "; reconnecting");
      modbus_close(context);
      connected = false;
      if (!wait_until(Clock::now() + retry)) return;
      continue;
    }
    // A write that took longer than the interval is not made up for with a burst.
    next_write = std::max(next_write + options_.write_interval, Clock::now());
    if (!wait_until(next_write)) return;
  }
}

}  // namespace tilth::modbus
