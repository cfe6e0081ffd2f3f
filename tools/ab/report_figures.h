// The figures a report shows, computed once from a comparison and handed to each of its
// writers (summary.json, summary.csv, conditions.csv, the HTML page, the terminal table):
// with a season's recordings, each condition's figures cost a pass over every frame.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "comparison.h"
#include "paired.h"

namespace tilth::ab {

// A variant's figures over some frames, and its comparison with the baseline on them.
struct VariantFigures {
  Figures figures;
  PairedFigures paired;
  std::string verdict;  // distance_verdict()
};

// The frames of one condition (conditions.h).
struct ConditionFigures {
  std::string name;
  std::string value;
  std::vector<VariantFigures> variants;  // in the comparison's order
};

struct ReportFigures {
  std::vector<VariantFigures> variants;                 // over every recording
  std::vector<std::vector<VariantFigures>> recordings;  // [variant][recording]
  std::vector<ConditionFigures> conditions;
};

ReportFigures report_figures(const Comparison& comparison);

}  // namespace tilth::ab
