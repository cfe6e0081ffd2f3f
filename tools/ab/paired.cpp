#include "paired.h"

#include <cmath>
#include <map>
#include <vector>

#include "statistics.h"

namespace tilth::ab {

PairedFigures paired_figures(const Comparison& comparison, std::size_t variant,
                             std::optional<std::size_t> recording) {
  PairedFigures paired;
  std::vector<double> recording_means;
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    if (recording && r != *recording) continue;
    std::map<std::uint64_t, const FrameResult*> baseline;
    for (const auto& frame : comparison.job(comparison.baseline, r).frames) {
      baseline.emplace(frame.record.frame_id, &frame);
    }
    double sum = 0.0;
    std::size_t count = 0;
    for (const auto& frame : comparison.job(variant, r).frames) {
      const auto found = baseline.find(frame.record.frame_id);
      if (found == baseline.end()) continue;
      const FrameResult& base = *found->second;
      paired.missed_by_variant_only += frame.missed && !base.missed ? 1 : 0;
      paired.missed_by_baseline_only += base.missed && !frame.missed ? 1 : 0;
      paired.false_valid_by_variant_only += frame.false_valid && !base.false_valid ? 1 : 0;
      paired.false_valid_by_baseline_only += base.false_valid && !frame.false_valid ? 1 : 0;
      if (!frame.error_mm || !base.error_mm) continue;
      sum += std::abs(*frame.error_mm) - std::abs(*base.error_mm);
      ++count;
    }
    if (count == 0) continue;
    paired.frames_with_both_errors += count;
    recording_means.push_back(sum / static_cast<double>(count));
  }
  paired.recordings = recording_means.size();
  if (recording_means.empty()) return paired;
  const ErrorStats stats = error_stats(recording_means);
  paired.abs_error_difference_mm = stats.mean_mm;
  paired.ci95_low_mm = stats.ci95_low_mm;
  paired.ci95_high_mm = stats.ci95_high_mm;
  return paired;
}

std::string distance_verdict(const Comparison& comparison, std::size_t variant,
                             const PairedFigures& paired) {
  if (variant == comparison.baseline) return "baseline";
  if (!paired.ci95_low_mm) return "too few recordings to tell";
  if (*paired.ci95_high_mm < 0.0) return "closer to the truth";
  if (*paired.ci95_low_mm > 0.0) return "farther from the truth";
  return "no clear difference";
}

}  // namespace tilth::ab
