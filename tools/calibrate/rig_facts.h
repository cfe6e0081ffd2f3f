// What neither a set of board views nor Basler's calibration file says about a rig: the
// ToF camera's depth scale and offsets, the camera models, and (for an import) the image
// sizes. They come from a base calibration file (--base), whose values options replace.
#pragma once

#include <string>

#include "command_line.h"
#include "tilth/calibration.h"

namespace tilth::calibrate {

// The base file (or an empty calibration) with the options applied. Throws tilth::Error
// naming the option when a value is malformed, or when there is no --base and a fact
// every rig needs is missing: --gray-to-mm and --z-offset-mm always, the sizes when
// `need_sizes` (an import: Basler's file holds none).
RigCalibration rig_facts(const cli::CommandLine& line, bool need_sizes);

}  // namespace tilth::calibrate
