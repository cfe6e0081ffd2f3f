// The self-contained HTML report of a comparison: tables of the figures, plots drawn by
// an inline script from the numbers embedded in the page, and the overlay images as
// data: URIs. Opening it needs no network and no other file.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "comparison.h"
#include "report_figures.h"
#include "report_numbers.h"

namespace tilth::ab {

std::string report_html(const Comparison& comparison, const ReportFigures& figures,
                        const nlohmann::ordered_json& summary, const Overlays& overlays);

}  // namespace tilth::ab
