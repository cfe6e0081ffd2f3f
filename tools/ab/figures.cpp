#include "figures.h"

namespace tilth::ab {
namespace {

void add_frames(const std::vector<FrameResult>& frames, Figures& figures,
                std::vector<double>& errors_mm) {
  for (const auto& frame : frames) {
    ++figures.frames;
    figures.measured += frame.record.measured ? 1 : 0;
    figures.valid += frame.record.valid ? 1 : 0;
    figures.expected_valid += frame.expected == Expectation::kValid ? 1 : 0;
    figures.no_visible_soil += frame.expected == Expectation::kNoVisibleSoil ? 1 : 0;
    figures.missed += frame.missed ? 1 : 0;
    figures.false_valid += frame.false_valid ? 1 : 0;
    if (frame.error_mm) errors_mm.push_back(*frame.error_mm);
    if (frame.record.mask) {
      if (!figures.mask) figures.mask.emplace();
      *figures.mask += *frame.record.mask;
      ++figures.mask_frames;
    }
  }
}

}  // namespace

std::string to_string(Expectation expectation) {
  switch (expectation) {
    case Expectation::kValid:
      return "valid";
    case Expectation::kNoVisibleSoil:
      return "no_visible_soil";
    case Expectation::kUnknown:
      break;
  }
  return "unknown";
}

std::vector<FrameResult> judge_frames(const std::vector<FrameRecord>& records,
                                      double no_soil_below) {
  std::vector<FrameResult> results;
  if (records.empty()) return results;
  const std::int64_t start_ns = records.front().device_timestamp_ns;
  for (const auto& record : records) {
    FrameResult result;
    result.record = record;
    result.time_s = static_cast<double>(record.device_timestamp_ns - start_ns) * 1e-9;
    if (record.truth_soil_fraction && *record.truth_soil_fraction < no_soil_below) {
      result.expected = Expectation::kNoVisibleSoil;
    } else if (record.truth_mm) {
      result.expected = Expectation::kValid;
    }
    if (record.valid && record.distance_mm && record.truth_mm) {
      result.error_mm = *record.distance_mm - *record.truth_mm;
    }
    result.missed = result.expected == Expectation::kValid && !record.valid;
    result.false_valid = result.expected == Expectation::kNoVisibleSoil && record.valid;
    results.push_back(std::move(result));
  }
  return results;
}

Figures figures_of(const std::vector<const std::vector<FrameResult>*>& recordings) {
  Figures figures;
  std::vector<double> errors_mm;
  for (const auto* frames : recordings) add_frames(*frames, figures, errors_mm);
  figures.error = error_stats(errors_mm);
  return figures;
}

}  // namespace tilth::ab
