// The colour-threshold residue segmentation (paper section 2.4), declared so that tests
// and benchmarks can make the stage without loading the plugin.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::segmentation {

StageDescriptor describe_color_threshold();

}  // namespace tilth::segmentation
