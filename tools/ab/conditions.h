// The conditions frames were recorded in, so that a report shows where a variant fails:
// residue cover bins from the truth mask, and the values of the recordings' tags.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "comparison.h"

namespace tilth::ab {

struct Condition {
  std::string name;   // "residue cover (truth mask)", "tag site"
  std::string value;  // "50-75 %", "north"
  std::function<bool(const Recording&, const FrameResult&)> holds;
};

// Every cover bin and tag value that at least one frame of the comparison is in, cover
// first, then tags by name and value.
std::vector<Condition> conditions_of(const Comparison& comparison);

// The comparison with only the frames in the condition (its jobs keep their stage times).
Comparison restricted_to(const Comparison& comparison, const Condition& condition);

}  // namespace tilth::ab
