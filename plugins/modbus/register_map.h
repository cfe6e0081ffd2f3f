// The Modbus register map of the ground distance: what each 16-bit register at an offset
// from base_register holds, and the encoding of one set of values into the block.
// docs/modbus.md is the same map as a PLC engineer reads it.
#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "tilth/messages/ground_distance.h"

namespace tilth::modbus {

// Offsets from base_register. 32-bit values start at even offsets so that a PLC can map
// the block onto a structure of DINT / REAL / UDINT / WORD without padding.
inline constexpr std::size_t kDistanceHundredthsMm = 0;  // int32, 0.01 mm
inline constexpr std::size_t kDistanceMm = 2;            // float32, mm
inline constexpr std::size_t kFrameCounter = 4;          // uint32
inline constexpr std::size_t kStatus = 6;                // bits, see StatusBit
inline constexpr std::size_t kSoilFraction = 7;          // 0..10000 = 0..100.00 %
inline constexpr std::size_t kConfidence = 8;            // 0..1000 = 0..1
inline constexpr std::size_t kHeartbeat = 9;             // wraps at 65535
inline constexpr std::size_t kAgeMs = 10;                // saturates at 65535
inline constexpr std::size_t kInvalidCause = 11;         // tilth::InvalidCause, 0 = valid
inline constexpr std::size_t kRegisterCount = 12;

enum StatusBit : std::uint16_t {
  kValid = 1u << 0,
  kCameraOk = 1u << 1,
  kTooLittleSoil = 1u << 2,
  kStale = 1u << 3,
  kPipelineError = 1u << 4,
  kImplausible = 1u << 5,    // not one surface, out of the rig's range, or low confidence
  kImageUnusable = 1u << 6,  // the colour image carries no information
  kHeld = 1u << 7,           // valid, but an earlier frame's distance (estimation.temporal)
};

// Which of the two 16-bit words of a 32-bit value comes first (at the lower address).
// Bytes inside a word are always big-endian, as Modbus requires.
enum class WordOrder { kHighFirst, kLowFirst };

// "big" (high word first) or "little"; throws tilth::Error for anything else.
WordOrder parse_word_order(std::string_view name);

// What the registers say at one instant, before encoding.
struct RegisterValues {
  bool valid = false;
  bool held = false;  // the valid distance is an earlier frame's; age counts from that frame
  bool camera_ok = false;
  InvalidCause cause = InvalidCause::kNone;  // of the measurement shown
  bool stale = true;
  bool pipeline_error = false;
  double distance_mm = 0.0;  // published only while valid
  double soil_fraction = 0.0;
  double confidence = 0.0;
  std::uint64_t frame_id = 0;  // its low 32 bits are published
  std::uint16_t heartbeat = 0;
  std::chrono::milliseconds age{0};
};

using RegisterBlock = std::array<std::uint16_t, kRegisterCount>;

RegisterBlock encode(const RegisterValues& values, WordOrder order);

// The two words of a 32-bit value in the order given.
std::array<std::uint16_t, 2> split_words(std::uint32_t value, WordOrder order);
// IEEE-754 binary32, encoded here: libmodbus 3.1.6's modbus_set_float_* swap bytes.
std::array<std::uint16_t, 2> split_words(float value, WordOrder order);

}  // namespace tilth::modbus
