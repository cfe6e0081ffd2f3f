// The ground estimators, declared so that tests and benchmarks can make them without
// loading the plugin.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::estimation {

StageDescriptor describe_ground_distance();
StageDescriptor describe_ground_plane();

}  // namespace tilth::estimation
