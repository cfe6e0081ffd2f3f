// What a camera stage asks of its camera: which one, how to configure it, how to stream
// it. Both camera stages declare these parameters (camera_param_specs) and read them
// with read_camera_settings.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "camera_features.h"
#include "pixel_formats.h"
#include "tilth/param_spec.h"
#include "tilth/params.h"

namespace tilth::aravis {

struct CameraSettings {
  std::string camera;  // address, serial, device id or MAC; "" = the only camera
  const std::vector<ImageFormat>* formats = nullptr;  // what the stage converts
  std::string pixel_format;                           // GenICam name to set; "" = keep the camera's
  double exposure_us = 0.0;                           // 0 = the camera's
  double gain = -1.0;                                 // negative = the camera's
  double frame_rate_hz = 0.0;                         // 0 = the camera's
  std::string trigger_mode;                           // "Off", "On"; "" = the camera's
  std::string trigger_source;                         // "" = the camera's
  double software_trigger_hz = 0.0;   // > 0: fired on the host clock's grid (software_trigger.h)
  std::int64_t packet_size = 0;       // bytes; 0 = the camera's
  std::int64_t packet_delay_ns = -1;  // negative = the camera's
  bool packet_socket = true;
  bool packet_resend = true;
  int receive_nice = -10;  // Aravis's receiving thread; 0 = as the process
  std::vector<FeatureSetting> features;
  std::string component;            // GenICam component to select and enable exclusively; "" = none
  std::string companion_component;  // enabled beside `component`, as another part; "" = none
  std::size_t buffers = 8;
  std::chrono::milliseconds timeout{0};  // 0 = two frame periods
  std::chrono::milliseconds reopen_after{1000};
};

std::vector<ParamSpec> camera_param_specs(const std::vector<ImageFormat>& formats);
CameraSettings read_camera_settings(const Params& params, const std::vector<ImageFormat>& formats);

}  // namespace tilth::aravis
