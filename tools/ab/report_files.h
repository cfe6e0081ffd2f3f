// A comparison's report as files (report.html, summary.json, summary.csv, frames.csv),
// and the table `tilth ab` prints after it: written alike by one run and by a merge of
// shards.
#pragma once

#include <cstddef>

#include "comparison.h"
#include "output_layout.h"
#include "report_figures.h"

namespace tilth::ab {

// `figures` are report_figures(comparison); `overlays` frames per recording are shown as
// mask overlays. Throws tilth::Error naming
// a file that cannot be written.
void write_report(const Comparison& comparison, const ReportFigures& figures,
                  const OutputLayout& layout, std::size_t overlays);

// One line per variant over every recording, then where the report is.
void print_summary(const Comparison& comparison, const ReportFigures& figures,
                   const OutputLayout& layout);

}  // namespace tilth::ab
