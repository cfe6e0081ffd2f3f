#include "register_map.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "tilth/error.h"

namespace tilth::modbus {
namespace {

// Rounds to the nearest integer and clamps into [low, high]; NaN becomes `low`.
std::int64_t scaled(double value, double scale, std::int64_t low, std::int64_t high) {
  const double rounded = std::round(value * scale);
  if (!(rounded > static_cast<double>(low))) return low;
  if (rounded >= static_cast<double>(high)) return high;
  return static_cast<std::int64_t>(rounded);
}

void put(RegisterBlock& block, std::size_t offset, std::array<std::uint16_t, 2> words) {
  block[offset] = words[0];
  block[offset + 1] = words[1];
}

// The status bit that tells a PLC the kind of cause.
std::uint16_t cause_bits(InvalidCause cause) {
  switch (cause) {
    case InvalidCause::kNone:
      return 0;
    case InvalidCause::kTooLittleSoil:
      return kTooLittleSoil;
    case InvalidCause::kNotOneSurface:
    case InvalidCause::kOutOfRange:
    case InvalidCause::kLowConfidence:
      return kImplausible;
    case InvalidCause::kImageUnusable:
      return kImageUnusable;
  }
  return 0;
}

}  // namespace

WordOrder parse_word_order(std::string_view name) {
  if (name == "big") return WordOrder::kHighFirst;
  if (name == "little") return WordOrder::kLowFirst;
  throw Error("word_order: expected 'big' or 'little', got '" + std::string(name) + "'");
}

std::array<std::uint16_t, 2> split_words(std::uint32_t value, WordOrder order) {
  const auto high = static_cast<std::uint16_t>(value >> 16);
  const auto low = static_cast<std::uint16_t>(value & 0xFFFFu);
  if (order == WordOrder::kHighFirst) return {high, low};
  return {low, high};
}

std::array<std::uint16_t, 2> split_words(float value, WordOrder order) {
  static_assert(std::numeric_limits<float>::is_iec559);
  return split_words(std::bit_cast<std::uint32_t>(value), order);
}

RegisterBlock encode(const RegisterValues& values, WordOrder order) {
  RegisterBlock block{};
  if (values.valid) {
    const auto hundredths =
        scaled(values.distance_mm, 100.0, std::numeric_limits<std::int32_t>::min(),
               std::numeric_limits<std::int32_t>::max());
    put(block, kDistanceHundredthsMm,
        split_words(static_cast<std::uint32_t>(static_cast<std::int32_t>(hundredths)), order));
    put(block, kDistanceMm, split_words(static_cast<float>(values.distance_mm), order));
  }
  put(block, kFrameCounter, split_words(static_cast<std::uint32_t>(values.frame_id), order));
  block[kStatus] = static_cast<std::uint16_t>(
      (values.valid ? kValid : 0) | (values.camera_ok ? kCameraOk : 0) | cause_bits(values.cause) |
      (values.stale ? kStale : 0) | (values.pipeline_error ? kPipelineError : 0) |
      (values.valid && values.held ? kHeld : 0));
  block[kSoilFraction] =
      static_cast<std::uint16_t>(scaled(values.soil_fraction, 10000.0, 0, 10000));
  block[kConfidence] = static_cast<std::uint16_t>(scaled(values.confidence, 1000.0, 0, 1000));
  block[kHeartbeat] = values.heartbeat;
  block[kInvalidCause] = static_cast<std::uint16_t>(values.cause);
  block[kAgeMs] = static_cast<std::uint16_t>(std::clamp<std::chrono::milliseconds::rep>(
      values.age.count(), 0, std::numeric_limits<std::uint16_t>::max()));
  return block;
}

}  // namespace tilth::modbus
