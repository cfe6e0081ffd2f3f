#include "mcap/ground_truth_message.h"

#include <nlohmann/json.hpp>

#include "mcap/json_time.h"
#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::mcap {

using nlohmann::json;

std::string ground_truth_schema() {
  const json schema = {
      {"title", "tilth.GroundTruth"},
      {"description",
       "What is known to be true about a frame: the mounting surface to soil distance "
       "(null when unknown); the residue mask, when known, is on /truth/mask"},
      {"type", "object"},
      {"properties",
       {{"timestamp", time_schema()},
        {"frame_id", {{"type", "string"}}},
        {"distance_mm", {{"type", {"number", "null"}}}},
        {"has_mask", {{"type", "boolean"}}}}}};
  return schema.dump();
}

std::string encode_ground_truth(std::optional<double> distance_mm, bool has_mask,
                                std::int64_t timestamp_ns) {
  json message = {{"timestamp", time_json(timestamp_ns)},
                  {"frame_id", "tof"},
                  {"distance_mm", nullptr},
                  {"has_mask", has_mask}};
  if (distance_mm) message["distance_mm"] = *distance_mm;
  return message.dump();
}

GroundTruthMessage decode_ground_truth(std::string_view text, const std::string& where) {
  const json message = parse_json(text, where);
  if (!message.is_object()) throw Error(where + ": message data is not a JSON object");
  try {
    GroundTruthMessage truth;
    const json& distance = message.at("distance_mm");
    if (!distance.is_null()) truth.distance_mm = distance.get<double>();
    truth.has_mask = message.at("has_mask").get<bool>();
    return truth;
  } catch (const json::exception& error) {
    throw Error(where + ": not a tilth.GroundTruth: " + error.what());
  }
}

}  // namespace tilth::mcap
