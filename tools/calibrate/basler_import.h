// Basler's blaze + ace calibration result (an OpenCV FileStorage file, usually
// calibration_<blazeSN>_<colorSN>.xml) read into a rig calibration.
#pragma once

#include <filesystem>

#include "tilth/calibration.h"

namespace tilth::calibrate {

// `rig` with both cameras' intrinsics and depth_to_color replaced by the file's. Throws
// tilth::Error naming the file and the node (colorCameraMatrix, colorDistortion,
// blazeCameraMatrix, blazeDistortion, rotation, translation) that is missing or not
// what was expected; the file's own syntax errors carry OpenCV's line.
RigCalibration import_basler(const std::filesystem::path& file, RigCalibration rig);

}  // namespace tilth::calibrate
