// Human-readable descriptions generated from stage descriptors: what `tilth plugins`
// and `tilth describe` print and what docs/stages.md is made from.
#pragma once

#include <string>

#include "framework/stage_registry.h"

namespace tilth {

// One line: "type  summary  (in: a:T, ...; out: b:T, ...)".
std::string stage_line(const StageRegistry::Entry& entry);
// Ports and the full parameter schema; Markdown when `markdown` is set.
std::string stage_reference(const StageRegistry::Entry& entry, bool markdown);

}  // namespace tilth
