// The per-frame lines a sinks.evaluation sink writes, read back.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "statistics.h"

namespace tilth::ab {

struct FrameRecord {
  std::uint64_t frame_id = 0;
  std::int64_t device_timestamp_ns = 0;
  bool measured = false;  // the chain produced a distance message
  bool valid = false;
  std::optional<double> distance_mm;  // when valid
  std::string invalid_reason;
  std::optional<double> truth_mm;
  std::optional<double> truth_soil_fraction;  // soil pixels / pixels of the truth mask
  std::optional<MaskCounts> mask;             // when both masks were there
};

// Throws tilth::Error naming the file and line of a malformed record.
std::vector<FrameRecord> read_frame_records(const std::filesystem::path& file);

}  // namespace tilth::ab
