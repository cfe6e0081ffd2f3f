// The ground truth of a frame in a Tilth recording: a small JSON message (schema
// tilth.GroundTruth) on its own channel, so Foxglove plots the distance; the mask, when
// known, is a RawImage on another channel.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace tilth::mcap {

inline constexpr std::string_view kGroundTruthSchemaName = "tilth.GroundTruth";
inline constexpr std::string_view kJsonSchemaEncoding = "jsonschema";
inline constexpr std::string_view kJsonEncoding = "json";

std::string ground_truth_schema();

std::string encode_ground_truth(std::optional<double> distance_mm, bool has_mask,
                                std::int64_t timestamp_ns);
struct GroundTruthMessage {
  std::optional<double> distance_mm;
  bool has_mask = false;
};
// Throws tilth::Error naming `where` for a message that is not a tilth.GroundTruth.
GroundTruthMessage decode_ground_truth(std::string_view json, const std::string& where);

}  // namespace tilth::mcap
