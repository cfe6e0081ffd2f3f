#include "report_files.h"

#include <cstdio>
#include <optional>
#include <string>

#include "overlays.h"
#include "report_html.h"
#include "report_numbers.h"

namespace tilth::ab {
namespace {

std::string column(const std::optional<double>& value, const char* format) {
  if (!value) return "-";
  char text[32];
  std::snprintf(text, sizeof text, format, *value);
  return text;
}

}  // namespace

void write_report(const Comparison& comparison, const ReportFigures& figures,
                  const OutputLayout& layout, std::size_t overlays) {
  Overlays shown;
  for (std::size_t r = 0; r < comparison.recordings.size(); ++r) {
    shown.push_back(disagreement_overlays(comparison, r, overlays));
  }
  const auto summary = summary_json(comparison, figures, shown);
  write_text(layout.summary_json(), summary.dump(2) + "\n");
  write_summary_csv(comparison, figures, layout.summary_csv());
  write_conditions_csv(comparison, figures, layout.conditions_csv());
  write_frames_csv(comparison, layout.frames_csv());
  write_text(layout.report(), report_html(comparison, figures, summary, shown));
}

void print_summary(const Comparison& comparison, const ReportFigures& figures,
                   const OutputLayout& layout) {
  std::printf("%-16s %7s %7s %7s %7s %11s %11s %7s  %s\n", "variant", "frames", "valid", "missed",
              "false", "mean|err|", "max|err|", "residue", "against the baseline");
  std::printf("%-16s %7s %7s %7s %7s %11s %11s %7s\n", "", "", "", "", "valid", "mm", "mm", "IoU");
  for (std::size_t v = 0; v < comparison.variants.size(); ++v) {
    const Figures& f = figures.variants[v].figures;
    const bool errors = f.error.count > 0;
    const PairedFigures& paired = figures.variants[v].paired;
    std::string against = figures.variants[v].verdict;
    if (v != comparison.baseline && paired.abs_error_difference_mm) {
      against += " (" + column(paired.abs_error_difference_mm, "%+.3f") + " mm)";
    }
    std::printf("%-16s %7zu %7zu %7zu %7zu %11s %11s %7s  %s\n",
                comparison.variants[v].name.c_str(), f.frames, f.valid, f.missed, f.false_valid,
                column(errors ? std::optional(f.error.mean_abs_mm) : std::nullopt, "%.3f").c_str(),
                column(errors ? std::optional(f.error.max_abs_mm) : std::nullopt, "%.3f").c_str(),
                column(f.mask ? f.mask->iou() : std::nullopt, "%.3f").c_str(), against.c_str());
  }
  std::printf("report: %s\n", layout.report().c_str());
}

}  // namespace tilth::ab
