// Ground distance: the measurement handed to the machine, with its validity and how
// much it can be trusted.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "tilth/message.h"

namespace tilth {

// Why a measurement is invalid, as outputs tell a machine's controller. The numbers are
// part of the Modbus register map (docs/modbus.md): never renumber them.
enum class InvalidCause : std::uint8_t {
  kNone = 0,           // valid
  kTooLittleSoil = 1,  // residue (or nothing) covers the region: too little soil visible
  kNotOneSurface = 2,  // the soil depths spread too widely, no surface fits them, or soil
                       // lies beyond the ground on every side (residue taken for soil)
  kOutOfRange = 3,     // the distance lies outside what the rig can physically see
  kLowConfidence = 4,  // the estimator trusts its own number too little
  kImageUnusable = 5,  // the colour image carries no information: clipped, black or flat
};

// "too_little_soil", "not_one_surface", ...: the names of the CSV and the docs.
std::string_view to_string(InvalidCause cause);

struct GroundDistance : MessageOf<GroundDistance> {
  static constexpr std::string_view kTypeName = "tilth.GroundDistance";

  double distance_mm = 0.0;                  // mounting surface to soil, along the optical axis
  bool valid = false;                        // false: do not use distance_mm
  InvalidCause cause = InvalidCause::kNone;  // why not valid
  std::string invalid_reason;                // the same in words, with the numbers
  double soil_fraction = 0.0;  // visible soil pixels / pixels in the region of interest
  std::int64_t soil_pixels = 0;
  double spread_mm = 0.0;            // robust spread of the soil depths
  double confidence = 0.0;           // 0..1
  std::optional<double> tilt_x_deg;  // ground tilt, when a plane was fitted
  std::optional<double> tilt_y_deg;
  // Set by estimation.temporal: the distance (valid) is an earlier frame's, held over a
  // frame that had none or an outlier, measured held_ms before this frame's capture.
  bool held = false;
  double held_ms = 0.0;

  // Marks the measurement invalid for `cause`: distance and confidence 0, never a guess.
  void invalidate(InvalidCause why, std::string reason);

  std::string summary() const override;
};

}  // namespace tilth
