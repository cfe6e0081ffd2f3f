// Judges each frame against its ground truth and sums frames up into the figures the
// report shows (docs/ab-testing.md defines each).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "frame_records.h"
#include "statistics.h"

namespace tilth::ab {

enum class Expectation {
  kUnknown,        // no truth distance and no truth mask
  kValid,          // a truth distance, and soil visible (or no truth mask)
  kNoVisibleSoil,  // the truth mask shows less soil than the threshold: must be invalid
};
std::string to_string(Expectation expectation);

struct FrameResult {
  FrameRecord record;
  double time_s = 0.0;  // device time since the recording's first frame
  Expectation expected = Expectation::kUnknown;
  std::optional<double> error_mm;  // measured minus true, for valid frames with a truth distance
  bool missed = false;             // expected valid, reported invalid (or nothing)
  bool false_valid = false;        // no visible soil, reported valid
};

// `no_soil_below`: the truth soil fraction under which a frame has no visible soil.
std::vector<FrameResult> judge_frames(const std::vector<FrameRecord>& records,
                                      double no_soil_below);

struct Figures {
  std::size_t frames = 0;
  std::size_t measured = 0;
  std::size_t valid = 0;
  std::size_t expected_valid = 0;
  std::size_t no_visible_soil = 0;
  std::size_t missed = 0;
  std::size_t false_valid = 0;
  ErrorStats error;
  std::optional<MaskCounts> mask;  // over the frames with both masks
  std::size_t mask_frames = 0;
};

// The figures of one recording, or of several pooled (frames in the order given).
Figures figures_of(const std::vector<const std::vector<FrameResult>*>& recordings);

}  // namespace tilth::ab
