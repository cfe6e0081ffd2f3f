// A variant against the baseline on the same frames: how much closer to the truth it is,
// with a 95 % interval that takes each recording, not each frame, as one observation
// (the frames of one recording are correlated), and the frames that one of the two gets
// wrong and the other right.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "comparison.h"

namespace tilth::ab {

struct PairedFigures {
  std::size_t frames_with_both_errors = 0;  // frames with an error value in both
  std::size_t recordings = 0;               // recordings with such frames
  // The mean over those recordings of each one's mean (|variant error| - |baseline error|)
  // over its frames: negative when the variant is closer to the truth.
  std::optional<double> abs_error_difference_mm;
  // Student's t over the recordings' means (as every 95 % interval of a report); needs two.
  std::optional<double> ci95_low_mm;
  std::optional<double> ci95_high_mm;
  std::size_t missed_by_variant_only = 0;  // the baseline reported them valid
  std::size_t missed_by_baseline_only = 0;
  std::size_t false_valid_by_variant_only = 0;
  std::size_t false_valid_by_baseline_only = 0;
};

// Over every recording, or over one.
PairedFigures paired_figures(const Comparison& comparison, std::size_t variant,
                             std::optional<std::size_t> recording = std::nullopt);

// What the interval says about the variant's distances: "baseline", "closer to the
// truth", "farther from the truth", "no clear difference", "too few recordings to tell".
std::string distance_verdict(const Comparison& comparison, std::size_t variant,
                             const PairedFigures& paired);

}  // namespace tilth::ab
