// Configuring an open camera from a stage's settings, in a fixed order (component,
// pixel format, trigger, exposure, gain, frame rate, packets, then the `features`), each
// value read back and logged; and what the stage needs to know afterwards.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include <arv.h>

#include "camera_settings.h"
#include "tilth/log.h"

namespace tilth::aravis {

struct CameraDescription {
  std::string label;                          // "Aravis Fake (serial TESTA) at 127.0.0.1"
  std::string pixel_format;                   // as the camera names it
  double frame_rate_hz = 0.0;                 // or the software trigger's; 0: neither known
  std::optional<std::uint32_t> component_id;  // of the selected component
  std::optional<std::uint32_t> companion_id;  // of the component enabled beside it
  std::optional<double> scale_mm;             // Scan3dCoordinateScale, when the camera has it
  std::optional<double> offset_mm;            // Scan3dCoordinateOffset
  std::size_t payload_bytes = 0;
};

// Throws tilth::Error naming the camera and the feature for anything it cannot set, and
// when the resulting pixel format is not one of settings.formats.
CameraDescription configure_camera(ArvCamera* camera, const std::string& label,
                                   const CameraSettings& settings, const Logger& log);

}  // namespace tilth::aravis
