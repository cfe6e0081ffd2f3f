// The depth.projection stage: raw ToF gray values -> depth in millimetres from the
// mounting surface along the optical axis (paper eq. 1). Declared for tests and
// benchmarks, which make the stage from its descriptor.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::depth {

StageDescriptor describe_projection();

}  // namespace tilth::depth
