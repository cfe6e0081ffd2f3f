#include "report_figures.h"

#include "conditions.h"

namespace tilth::ab {
namespace {

VariantFigures variant_figures(const Comparison& comparison, std::size_t variant, Figures figures,
                               std::optional<std::size_t> recording = std::nullopt) {
  PairedFigures paired = paired_figures(comparison, variant, recording);
  std::string verdict = distance_verdict(comparison, variant, paired);
  return {std::move(figures), paired, std::move(verdict)};
}

}  // namespace

ReportFigures report_figures(const Comparison& comparison) {
  ReportFigures report;
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    report.variants.push_back(variant_figures(comparison, v, comparison.variant_figures(v)));
    auto& by_recording = report.recordings.emplace_back();
    for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
      by_recording.push_back(variant_figures(comparison, v, comparison.recording_figures(v, r), r));
    }
  }
  for (const Condition& condition : conditions_of(comparison)) {
    const Comparison part = restricted_to(comparison, condition);
    ConditionFigures& figures =
        report.conditions.emplace_back(ConditionFigures{condition.name, condition.value, {}});
    for (std::size_t v = 0; v < part.variants.size(); ++v) {
      figures.variants.push_back(variant_figures(part, v, part.variant_figures(v)));
    }
  }
  return report;
}

}  // namespace tilth::ab
