// Ground distance: the measurement handed to the machine, with its validity and how
// much it can be trusted.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "tilth/message.h"

namespace tilth {

struct GroundDistance : MessageOf<GroundDistance> {
  static constexpr std::string_view kTypeName = "tilth.GroundDistance";

  double distance_mm = 0.0;  // mounting surface to soil, along the optical axis
  bool valid = false;        // false: do not use distance_mm
  std::string invalid_reason;
  double soil_fraction = 0.0;  // visible soil pixels / pixels in the region of interest
  std::int64_t soil_pixels = 0;
  double spread_mm = 0.0;            // robust spread of the soil depths
  double confidence = 0.0;           // 0..1
  std::optional<double> tilt_x_deg;  // ground tilt, when a plane was fitted
  std::optional<double> tilt_y_deg;

  std::string summary() const override;
};

}  // namespace tilth
