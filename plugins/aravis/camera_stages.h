// The Aravis camera stages, declared so that tests can make them without loading the
// plugin.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::aravis {

StageDescriptor describe_tof_camera();
StageDescriptor describe_color_camera();

}  // namespace tilth::aravis
