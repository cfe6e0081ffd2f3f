#include "camera_settings.h"

#include "tilth/error.h"

namespace tilth::aravis {
namespace {

constexpr const char* kCurrent = "current";
constexpr const char* kHostClock = "host_clock";

}  // namespace

std::vector<ParamSpec> camera_param_specs(const std::vector<ImageFormat>& formats) {
  std::vector<std::string> format_choices = {kCurrent};
  for (const auto& name : format_names(formats)) format_choices.push_back(name);
  return {
      ParamSpec::string("camera", "")
          .describe("which camera: IPv4 address, serial number, device id or MAC address; "
                    "empty = the only GigE Vision camera found (open simulators on loopback "
                    "by address)"),
      ParamSpec::choice("pixel_format", format_choices, kCurrent)
          .describe("GenICam PixelFormat to set; current = keep the camera's, which must be "
                    "one of these"),
      ParamSpec::number("exposure_us", 0.0)
          .range(0.0, std::nullopt)
          .in_unit("us")
          .describe("exposure time (ExposureTime or ExposureTimeAbs); 0 = the camera's"),
      ParamSpec::number("gain", -1.0)
          .describe("gain in the camera's unit (Gain, dB on most cameras, or GainRaw); "
                    "negative = the camera's"),
      ParamSpec::number("frame_rate", 0.0)
          .range(0.0, std::nullopt)
          .in_unit("Hz")
          .describe("acquisition frame rate (AcquisitionFrameRate); 0 = the camera's; with "
                    "trigger_mode host_clock, the rate of the triggers instead"),
      ParamSpec::choice("trigger_mode", {kCurrent, "off", "on", kHostClock}, kCurrent)
          .describe("frame start trigger (TriggerSelector FrameStart, TriggerMode): off = "
                    "free running, on = one frame per trigger, host_clock = a software "
                    "trigger at frame_rate on a grid of the host's clock that every camera at "
                    "that rate shares, so that they expose together"),
      ParamSpec::string("trigger_source", "")
          .describe("TriggerSource when triggered (Line1, Software, ...); empty = the "
                    "camera's"),
      ParamSpec::integer("packet_size", 0)
          .range(0, 65535)
          .in_unit("bytes")
          .describe("stream packet size (GevSCPSPacketSize); 0 = the camera's"),
      ParamSpec::integer("packet_delay_ns", -1)
          .range(-1, std::nullopt)
          .in_unit("ns")
          .describe("delay between stream packets (GevSCPD); -1 = the camera's"),
      ParamSpec::boolean("packet_socket", true)
          .describe("receive with Aravis's packet socket (needs CAP_NET_RAW); turn off for "
                    "cameras on loopback, where it sees every packet twice"),
      ParamSpec::boolean("packet_resend", true)
          .describe("ask the camera to resend lost stream packets"),
      ParamSpec::integer("receive_nice", -10)
          .range(-20, 19)
          .describe("nice level of the thread receiving the stream, so that busy stages do "
                    "not make it miss packets; below 0 needs CAP_SYS_NICE, 0 = as the process"),
      ParamSpec::json("features", nlohmann::json::object())
          .describe("GenICam features set after the parameters above, each read back and "
                    "logged: {\"Name\": value, ...}, or [{\"Name\": value}, ...] to fix the "
                    "order (an object's members arrive sorted by name)"),
      ParamSpec::integer("buffers", 8)
          .range(2, 256)
          .describe("stream buffers, allocated once; a frame arriving while the graph holds "
                    "them all is dropped and counted late"),
      ParamSpec::integer("timeout_ms", 0)
          .range(0, std::nullopt)
          .in_unit("ms")
          .describe("no frame for this long: frames go on without an image, status not "
                    "streaming, once per frame period; 0 = two frame periods"),
      ParamSpec::integer("reopen_after_ms", 1000)
          .range(1, std::nullopt)
          .in_unit("ms")
          .describe("no frame for this long (or the camera's control lost): the camera is "
                    "closed and reopened, with growing pauses until it answers"),
  };
}

CameraSettings read_camera_settings(const Params& params, const std::vector<ImageFormat>& formats) {
  CameraSettings settings;
  settings.camera = params.string("camera");
  settings.formats = &formats;
  const std::string format = params.string("pixel_format");
  if (format != kCurrent) settings.pixel_format = format;
  settings.exposure_us = params.number("exposure_us");
  settings.gain = params.number("gain");
  settings.frame_rate_hz = params.number("frame_rate");
  const std::string trigger = params.string("trigger_mode");
  if (trigger != kCurrent) settings.trigger_mode = trigger == "off" ? "Off" : "On";
  settings.trigger_source = params.string("trigger_source");
  if (trigger == kHostClock) {
    if (settings.frame_rate_hz <= 0.0) {
      throw Error("trigger_mode host_clock needs frame_rate: the rate of the triggers, in Hz");
    }
    if (!settings.trigger_source.empty() && settings.trigger_source != "Software") {
      throw Error("trigger_mode host_clock fires TriggerSource Software; trigger_source is '" +
                  settings.trigger_source + "'");
    }
    settings.trigger_source = "Software";
    settings.software_trigger_hz = settings.frame_rate_hz;
    settings.frame_rate_hz = 0.0;  // the triggers set the rate, not AcquisitionFrameRate
  }
  settings.packet_size = params.integer("packet_size");
  settings.packet_delay_ns = params.integer("packet_delay_ns");
  settings.packet_socket = params.boolean("packet_socket");
  settings.packet_resend = params.boolean("packet_resend");
  settings.receive_nice = static_cast<int>(params.integer("receive_nice"));
  settings.features = parse_feature_settings(params.json("features"));
  settings.buffers = static_cast<std::size_t>(params.integer("buffers"));
  settings.timeout = std::chrono::milliseconds(params.integer("timeout_ms"));
  settings.reopen_after = std::chrono::milliseconds(params.integer("reopen_after_ms"));
  return settings;
}

}  // namespace tilth::aravis
