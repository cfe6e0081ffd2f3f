// The time of a JSON message in a Tilth recording, {sec, nsec} as Foxglove's schemas
// have it, and its JSON Schema.
#pragma once

#include <cstdint>

#include <nlohmann/json.hpp>

namespace tilth::mcap {

nlohmann::json time_schema();
nlohmann::json time_json(std::int64_t timestamp_ns);

}  // namespace tilth::mcap
