#include "mcap/json_time.h"

namespace tilth::mcap {

constexpr std::int64_t kNsPerSecond = 1'000'000'000;

nlohmann::json time_schema() {
  return {{"type", "object"},
          {"title", "time"},
          {"properties",
           {{"sec", {{"type", "integer"}, {"minimum", 0}}},
            {"nsec", {{"type", "integer"}, {"minimum", 0}, {"maximum", 999999999}}}}}};
}

nlohmann::json time_json(std::int64_t timestamp_ns) {
  return {{"sec", timestamp_ns / kNsPerSecond}, {"nsec", timestamp_ns % kNsPerSecond}};
}

}  // namespace tilth::mcap
