// modbus.output: hands the ground distance to the machine's PLC over Modbus TCP, either
// as a server the PLC polls or as a client that writes into the PLC's registers. The
// sink only records the newest measurement; the server or client thread publishes it,
// so a slow or absent PLC never holds up the graph. docs/modbus.md has the register map.
#include <arpa/inet.h>

#include <chrono>
#include <memory>

#include "ipv4_ranges.h"
#include "latest_measurement.h"
#include "modbus_client.h"
#include "modbus_server.h"
#include "register_map.h"
#include "tilth/messages/camera_status.h"
#include "tilth/plugin.h"

namespace tilth::modbus {
namespace {

constexpr const char* kAnyAddress = "0.0.0.0";

std::string ipv4_address(const Params& params, bool client) {
  const std::string address = params.string("address");
  in_addr parsed{};
  if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) {
    throw Error("parameter 'address': expected an IPv4 address such as 192.168.1.10, got '" +
                address + "'");
  }
  if (client && address == kAnyAddress) {
    throw Error("parameter 'address': mode 'client' needs the PLC's IP address, not " +
                std::string(kAnyAddress));
  }
  return address;
}

class ModbusOutput final : public Sink {
 public:
  enum Port { kDistance = 0, kCameras = 1 };

  explicit ModbusOutput(const StageContext& context)
      : latest_(std::chrono::milliseconds(context.params.integer("stale_timeout_ms"))) {
    const Params& params = context.params;
    const bool client = params.string("mode") == "client";
    const std::string address = ipv4_address(params, client);
    const auto port = static_cast<int>(params.integer("port"));
    const auto unit_id = static_cast<int>(params.integer("unit_id"));
    const auto base_register = static_cast<int>(params.integer("base_register"));
    const WordOrder word_order = parse_word_order(params.string("word_order"));
    if (client) {
      client_ = std::make_unique<ModbusClient>(
          ClientOptions{address, port, unit_id, base_register, word_order,
                        std::chrono::milliseconds(params.integer("write_interval_ms"))},
          latest_, context.log);
    } else {
      server_ = std::make_unique<ModbusServer>(
          ServerOptions{address, port, unit_id, base_register, word_order,
                        Ipv4Ranges::parse("plc_address", params.json("plc_address")),
                        static_cast<int>(params.integer("plc_clients")),
                        Ipv4Ranges::parse("allow", params.json("allow")),
                        static_cast<int>(params.integer("max_clients")),
                        std::chrono::milliseconds(params.integer("idle_timeout_ms"))},
          latest_, context.log);
    }
  }

  void consume(const Frame& frame) override {
    if (const Packet& cameras = frame.input(kCameras); !cameras.empty()) {
      latest_.update_cameras(cameras.get<CameraStatus>().streaming);
    }
    if (frame.input(kDistance).empty()) {
      latest_.update_missing(LatestMeasurement::Clock::now());
      return;
    }
    const auto& info = frame.info();
    // How old the frame already is, on the host clock the source stamped it with.
    LatestMeasurement::Clock::duration capture_age{0};
    if (info.host_timestamp_ns != 0) {
      capture_age = std::chrono::duration_cast<LatestMeasurement::Clock::duration>(
          std::chrono::system_clock::now().time_since_epoch() -
          std::chrono::nanoseconds(info.host_timestamp_ns));
    }
    latest_.update(info.frame_id, frame.input<GroundDistance>(kDistance),
                   LatestMeasurement::Clock::now(), capture_age);
  }

  void finish() override {
    server_.reset();
    client_.reset();
  }

 private:
  LatestMeasurement latest_;  // first: outlives the threads that read it
  std::unique_ptr<ModbusServer> server_;
  std::unique_ptr<ModbusClient> client_;
};

StageDescriptor describe() {
  constexpr auto kLastBase = 65536 - static_cast<std::int64_t>(kRegisterCount);
  StageDescriptor d;
  d.type = "modbus.output";
  d.summary = "hands the ground distance to a PLC over Modbus TCP (docs/modbus.md)";
  d.inputs = {
      PortSpec::of<GroundDistance>("distance", "the measurement; a frame without one clears valid")
          .optional(),
      PortSpec::of<CameraStatus>("cameras", "the cameras' health, for the camera_ok bit")
          .optional(),
  };
  d.params = {
      ParamSpec::choice("mode", {"server", "client"}, "server")
          .describe("server: the PLC polls Tilth; client: Tilth writes into the PLC"),
      ParamSpec::string("address", kAnyAddress)
          .describe("server: IPv4 address to listen on (0.0.0.0 = all); client: the PLC's"),
      ParamSpec::integer("port", 502).range(1, 65535).describe("TCP port"),
      ParamSpec::integer("unit_id", 1)
          .range(0, 247)
          .describe("Modbus unit id (server: also answers 0 and 255)"),
      ParamSpec::integer("base_register", 0)
          .range(0, kLastBase)
          .describe("address of the block's first register (0-based, PDU addressing)"),
      ParamSpec::choice("word_order", {"big", "little"}, "big")
          .describe("32-bit values: big = high word first; bytes in a word are big-endian"),
      ParamSpec::integer("stale_timeout_ms", 200)
          .range(1, 60000)
          .in_unit("ms")
          .describe("without a new measurement for this long, valid clears and stale sets"),
      ParamSpec::integer("write_interval_ms", 40)
          .range(1, 60000)
          .in_unit("ms")
          .describe("client: time between writes"),
      ParamSpec::json("plc_address", nlohmann::json::array())
          .describe("server: the PLC's IPv4 addresses or CIDR blocks; slots of their own"),
      ParamSpec::integer("plc_clients", 2)
          .range(1, 16)
          .describe("server: connections kept for the PLC; never closed for other clients"),
      ParamSpec::json("allow", nlohmann::json::array())
          .describe("server: IPv4 addresses or CIDR blocks other clients may come from; [] = any"),
      ParamSpec::integer("max_clients", 8)
          .range(1, 256)
          .describe("server: other clients served at once; more are refused"),
      ParamSpec::integer("idle_timeout_ms", 5000)
          .range(0, 600000)
          .in_unit("ms")
          .describe("server: other clients without a request for this long are closed; 0 = never"),
  };
  d.create = factory<ModbusOutput>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::modbus
