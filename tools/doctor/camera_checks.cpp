#include "camera_checks.h"

#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include <arv.h>

#include "aravis/device_list.h"
#include "aravis/gobject_ptr.h"
#include "network_interfaces.h"
#include "tilth/error.h"

namespace tilth::doctor {
namespace {

using aravis::GErrorSlot;
using aravis::GObjectPtr;

constexpr int kJumboMtu = 8000;
constexpr int kStreamBuffers = 10;
// A few seconds of frames, stamped by the host when they arrive, resolve a clock rate to a
// few hundred ppm: enough for gross faults (timestamps in another unit, a clock far off),
// not for crystal drift, which PTP removes.
constexpr double kClockAgreementPpm = 10'000.0;

// What a few seconds of streaming showed.
struct StreamStats {
  std::string error;  // empty when the stream ran
  std::uint64_t frames = 0;
  std::uint64_t incomplete = 0;
  std::uint64_t resent_packets = 0;
  std::uint64_t missing_packets = 0;
  double seconds = 0.0;
  std::optional<double> clock_rate;  // device time / host time over the window
};

struct Camera {
  std::string address;
  std::string label;
  GObjectPtr<ArvCamera> handle;
  StreamStats stats;
};

std::string fixed(double value, int decimals) {
  std::ostringstream text;
  text.precision(decimals);
  text << std::fixed << value;
  return text.str();
}

StreamStats failed_stream(std::string error) {
  StreamStats stats;
  stats.error = std::move(error);
  return stats;
}

// The stream's receiving thread at the nice level tilth's camera stages give theirs by
// default (their receive_nice), so that the doctor sees the frames a graph would.
constexpr int kReceiveNice = -10;

void receive_as_tilth_does(void*, ArvStreamCallbackType type, ArvBuffer*) {
  if (type == ARV_STREAM_CALLBACK_TYPE_INIT) {
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), kReceiveNice);  // as root only
  }
}

StreamStats stream(ArvCamera* camera, std::chrono::milliseconds duration) {
  StreamStats stats;
  GErrorSlot error;
  const guint payload = arv_camera_get_payload(camera, error.out());
  if (error.failed()) return failed_stream("reading its payload size: " + error.message());
  GObjectPtr<ArvStream> stream(
      arv_camera_create_stream(camera, receive_as_tilth_does, nullptr, error.out()));
  if (error.failed()) return failed_stream("opening a stream: " + error.message());
  for (int i = 0; i < kStreamBuffers; ++i) {
    arv_stream_push_buffer(stream.get(), arv_buffer_new(payload, nullptr));
  }
  arv_camera_set_acquisition_mode(camera, ARV_ACQUISITION_MODE_CONTINUOUS, nullptr);
  arv_camera_start_acquisition(camera, error.out());
  if (error.failed()) return failed_stream("starting acquisition: " + error.message());
  std::optional<std::pair<guint64, guint64>> first;
  std::pair<guint64, guint64> last{};
  const auto start = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - start < duration) {
    ArvBuffer* buffer = arv_stream_timeout_pop_buffer(stream.get(), 100'000);
    if (buffer == nullptr) continue;
    if (arv_buffer_get_status(buffer) == ARV_BUFFER_STATUS_SUCCESS) {
      ++stats.frames;
      last = {arv_buffer_get_timestamp(buffer), arv_buffer_get_system_timestamp(buffer)};
      if (!first) first = last;
    } else {
      ++stats.incomplete;
    }
    arv_stream_push_buffer(stream.get(), buffer);
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  arv_camera_stop_acquisition(camera, nullptr);
  guint64 resent = 0;
  guint64 missing = 0;
  if (ARV_IS_GV_STREAM(stream.get())) {
    arv_gv_stream_get_statistics(ARV_GV_STREAM(stream.get()), &resent, &missing);
  }
  stats.resent_packets = resent;
  stats.missing_packets = missing;
  if (first && last.second > first->second && last.first > first->first) {
    stats.clock_rate = static_cast<double>(last.first - first->first) /
                       static_cast<double>(last.second - first->second);
  }
  return stats;
}

Finding address_finding(const Camera& camera, const std::vector<NetworkInterface>& interfaces,
                        const std::vector<aravis::DeviceEntry>& devices) {
  Finding finding{"camera " + camera.address + ": address"};
  const auto address = parse_ipv4(camera.address);
  const auto interface = address ? interface_for(interfaces, *address) : std::nullopt;
  if (!interface) {
    finding.verdict = Verdict::kFailed;
    finding.detail = "on no subnet of this host's interfaces";
    finding.fix =
        "give the camera an address on the NIC's subnet (its vendor's IP tool, or "
        "arv-tool-0.8), or the NIC one on the camera's (ip addr add)";
    return finding;
  }
  finding.detail = "on " + interface->name + " (" + ipv4_text(interface->address) + ")";
  for (const auto& other : interfaces) {
    if (other.address == *address) {
      finding.verdict = Verdict::kFailed;
      finding.detail += ": the host's own interface " + other.name + " has this address";
      finding.fix = "give the camera or the interface another address";
      return finding;
    }
  }
  std::map<std::string, int> macs;
  for (const auto& device : devices) {
    if (device.address == camera.address) ++macs[device.physical_id];
  }
  if (macs.size() > 1) {
    finding.verdict = Verdict::kFailed;
    finding.detail += ": " + std::to_string(macs.size()) + " devices answer with this address";
    finding.fix = "give each camera an address of its own";
  }
  return finding;
}

Finding packet_finding(const Camera& camera, const std::vector<NetworkInterface>& interfaces) {
  Finding finding{"camera " + camera.address + ": packet size"};
  GErrorSlot error;
  const guint packet = arv_camera_gv_get_packet_size(camera.handle.get(), error.out());
  if (error.failed()) {
    finding.verdict = Verdict::kWarning;
    finding.detail = "cannot read GevSCPSPacketSize: " + error.message();
    return finding;
  }
  const auto address = parse_ipv4(camera.address);
  const auto interface = address ? interface_for(interfaces, *address) : std::nullopt;
  if (!interface) {
    finding.detail = std::to_string(packet) + " bytes (no interface to compare with)";
    return finding;
  }
  finding.detail = std::to_string(packet) + " bytes, MTU of " + interface->name + " " +
                   std::to_string(interface->mtu);
  if (static_cast<int>(packet) > interface->mtu) {
    finding.verdict = Verdict::kFailed;
    finding.detail += ": every stream packet is larger than the interface takes";
    finding.fix = "ip link set " + interface->name + " mtu 9000 (jumbo frames, if the switch " +
                  "takes them), or the camera stage's packet_size at most " +
                  std::to_string(interface->mtu);
  } else if (interface->mtu < kJumboMtu) {
    finding.verdict = Verdict::kWarning;
    finding.detail += ": no jumbo frames, about six times the packets per frame";
    finding.fix = "ip link set " + interface->name + " mtu 9000 and packet_size 8192, where " +
                  "the NIC and switch take jumbo frames";
  }
  return finding;
}

// Frames not assembled in time although no packet was missing, in percent of the frames
// streamed: up to this a warning (a busy moment), above it a failure.
constexpr std::uint64_t kBusyHostFailPercent = 5;

Finding stream_finding(const Camera& camera) {
  Finding finding{"camera " + camera.address + ": streaming"};
  const StreamStats& stats = camera.stats;
  if (!stats.error.empty()) {
    finding.verdict = Verdict::kFailed;
    finding.detail = stats.error;
    finding.fix = "is another program (a running tilth graph) controlling the camera?";
    return finding;
  }
  finding.detail = std::to_string(stats.frames) + " frames in " + fixed(stats.seconds, 1) + " s (" +
                   fixed(stats.frames / std::max(stats.seconds, 1e-9), 1) + " frames/s), " +
                   std::to_string(stats.incomplete) + " incomplete, " +
                   std::to_string(stats.missing_packets) + " packets missing, " +
                   std::to_string(stats.resent_packets) + " resent";
  if (stats.frames == 0 || stats.missing_packets > 0) {
    finding.verdict = Verdict::kFailed;
    finding.fix =
        "lost packets: raise net.core.rmem_max, enable jumbo frames, give the "
        "cameras a NIC of their own, check cables and switch";
  } else if (stats.incomplete > 0) {
    // Every packet came, yet a frame was not assembled in time: the host, not the network.
    finding.verdict = stats.incomplete * 100 > stats.frames * kBusyHostFailPercent
                          ? Verdict::kFailed
                          : Verdict::kWarning;
    finding.fix =
        "frames timed out with no packet missing: this host was too busy to take them in; "
        "lower its load, or raise the camera stage's receive priority (receive_nice)";
  } else if (stats.resent_packets > 0) {
    finding.verdict = Verdict::kWarning;
    finding.fix = "packets were resent: the link or the receiving host is near its limit";
  }
  return finding;
}

std::string ptp_state(ArvCamera* camera) {
  for (const char* feature : {"PtpEnable", "GevIEEE1588"}) {
    if (arv_camera_is_feature_available(camera, feature, nullptr)) {
      const bool on = arv_camera_get_boolean(camera, feature, nullptr);
      return std::string(feature) + (on ? " on" : " off");
    }
  }
  return "no PTP";
}

Finding clocks_finding(const std::vector<Camera*>& cameras) {
  Finding finding{"camera clocks"};
  std::vector<std::pair<const Camera*, double>> rates;
  for (const Camera* camera : cameras) {
    if (camera->stats.clock_rate) rates.emplace_back(camera, *camera->stats.clock_rate);
  }
  if (rates.empty()) {
    finding.verdict = Verdict::kWarning;
    finding.detail = "no camera streamed two frames: clock rates not compared";
    return finding;
  }
  double low = rates.front().second;
  double high = low;
  for (const auto& [camera, rate] : rates) {
    finding.detail += (finding.detail.empty() ? "" : "; ") + camera->address + " " +
                      fixed((rate - 1.0) * 1e6, 0) + " ppm against the host, " +
                      ptp_state(camera->handle.get());
    low = std::min(low, rate);
    high = std::max(high, rate);
  }
  if ((high - low) * 1e6 > kClockAgreementPpm) {
    finding.verdict = Verdict::kWarning;
    finding.detail += ": the cameras' clocks drift " + fixed((high - low) * 1e6, 0) +
                      " ppm apart, so pairing by device time drifts";
    finding.fix = "enable PTP (IEEE 1588) on both cameras, or pair by host time";
  }
  return finding;
}

}  // namespace

CameraChecks check_cameras(const std::vector<std::string>& names,
                           std::chrono::milliseconds streaming) {
  CameraChecks checks;
  const std::vector<aravis::DeviceEntry> devices = aravis::discover_devices();
  std::vector<Camera> cameras;
  if (names.empty()) {
    for (const auto& device : devices) cameras.push_back({device.address, device.label(), {}, {}});
    if (cameras.empty()) {
      checks.findings.push_back(
          {"cameras", Verdict::kFailed, "no GigE Vision camera answered a discovery",
           "check power and cables, and that a NIC is on the cameras' subnet"});
      return checks;
    }
  } else {
    for (const auto& name : names) {
      try {
        const std::string address = aravis::resolve_camera_address(name);
        cameras.push_back({address, name, {}, {}});
      } catch (const Error& error) {
        checks.findings.push_back({"camera " + name, Verdict::kFailed, error.what(),
                                   "tilth cameras lists the cameras that answer"});
      }
    }
  }
  std::string found;
  for (const auto& device : devices) found += (found.empty() ? "" : "; ") + device.label();
  checks.findings.insert(checks.findings.begin(),
                         {"cameras", Verdict::kOk,
                          found.empty() ? "none answered a discovery" : "answered: " + found, ""});

  const std::vector<NetworkInterface> interfaces = ipv4_interfaces();
  std::vector<Camera*> opened;
  for (auto& camera : cameras) {
    checks.findings.push_back(address_finding(camera, interfaces, devices));
    GErrorSlot error;
    camera.handle.reset(arv_camera_new(camera.address.c_str(), error.out()));
    if (error.failed()) {
      camera.handle.reset();
      checks.findings.push_back({"camera " + camera.address + ": control", Verdict::kFailed,
                                 "cannot open it: " + error.message(),
                                 "is another program controlling it?"});
      continue;
    }
    checks.findings.push_back(packet_finding(camera, interfaces));
    const guint payload = arv_camera_get_payload(camera.handle.get(), nullptr);
    checks.largest_frame_bytes = std::max<std::uint64_t>(checks.largest_frame_bytes, payload);
    opened.push_back(&camera);
  }
  // All cameras at once, as a graph streams them.
  std::vector<std::thread> threads;
  for (Camera* camera : opened) {
    threads.emplace_back(
        [camera, streaming] { camera->stats = stream(camera->handle.get(), streaming); });
  }
  for (auto& thread : threads) thread.join();
  for (const Camera* camera : opened) checks.findings.push_back(stream_finding(*camera));
  if (!opened.empty()) checks.findings.push_back(clocks_finding(opened));
  return checks;
}

}  // namespace tilth::doctor
