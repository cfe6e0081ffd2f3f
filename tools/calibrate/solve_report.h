// The report `tilth calibrate solve` writes beside the calibration: how well the board's
// corners fit (per camera, stereo, per view), which parts of each image the board
// covered, and how uncertain the rotation and translation between the cameras are.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "rig_solver.h"

namespace tilth::calibrate {

// `calibration` names the file written; `options` are the board and the ToF mode.
nlohmann::json solve_report(const SolveResult& result, const SolveOptions& options,
                            const std::string& calibration);

}  // namespace tilth::calibrate
