#include "frame_records.h"

#include <fstream>

#include <nlohmann/json.hpp>

#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::ab {
namespace {

using json = nlohmann::json;

std::optional<double> optional_number(const json& line, const char* key) {
  if (!line.contains(key) || line[key].is_null()) return std::nullopt;
  return line[key].get<double>();
}

MaskCounts mask_counts(const json& mask) {
  MaskCounts counts;
  counts.tp = mask.at("tp").get<std::int64_t>();
  counts.fp = mask.at("fp").get<std::int64_t>();
  counts.fn = mask.at("fn").get<std::int64_t>();
  counts.tn = mask.at("tn").get<std::int64_t>();
  counts.unknown = mask.at("unknown").get<std::int64_t>();
  return counts;
}

}  // namespace

std::vector<FrameRecord> read_frame_records(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot read the frame records");
  std::vector<FrameRecord> records;
  std::size_t number = 0;
  for (std::string text; std::getline(in, text);) {
    ++number;
    if (text.empty()) continue;
    try {
      const json line = parse_json(text, file.string() + ":" + std::to_string(number));
      FrameRecord record;
      record.frame_id = line.at("frame_id").get<std::uint64_t>();
      record.device_timestamp_ns = line.at("device_timestamp_ns").get<std::int64_t>();
      record.measured = line.at("measured").get<bool>();
      record.valid = line.at("valid").get<bool>();
      record.distance_mm = optional_number(line, "distance_mm");
      if (line.contains("invalid_reason")) {
        record.invalid_reason = line["invalid_reason"].get<std::string>();
      }
      record.truth_mm = optional_number(line, "truth_mm");
      record.truth_soil_fraction = optional_number(line, "truth_soil_fraction");
      if (line.contains("mask") && !line["mask"].is_null()) record.mask = mask_counts(line["mask"]);
      records.push_back(std::move(record));
    } catch (const json::exception& error) {
      throw Error(file.string() + ":" + std::to_string(number) +
                  ": not a sinks.evaluation record: " + error.what());
    }
  }
  return records;
}

}  // namespace tilth::ab
