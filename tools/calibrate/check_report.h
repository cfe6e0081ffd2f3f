// The report `tilth calibrate check` writes with --report: per frame and for the
// recording, the edges used, the distances from depth edges to colour edges, the best
// offset and the verdict.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "calibration_check.h"

namespace tilth::calibrate {

// `recording` and `calibration` (the file checked, or "" for the recording's own) name
// what was checked.
nlohmann::json check_report(const CheckResult& result, const std::string& recording,
                            const std::string& calibration);

}  // namespace tilth::calibrate
