// The ground estimators and the temporal filter after them, declared so that tests and benchmarks
// can make them without loading the plugin.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::estimation {

StageDescriptor describe_ground_distance();
StageDescriptor describe_ground_plane();
StageDescriptor describe_temporal();

}  // namespace tilth::estimation
