// The Tilth release this SDK belongs to, stamped into what Tilth writes (CSV rows, MCAP
// metadata, A/B reports) and printed by `tilth --version`.
#pragma once

#include <string_view>

namespace tilth {

// "0.1.0": the project's version (CMakeLists.txt).
std::string_view version();

}  // namespace tilth
