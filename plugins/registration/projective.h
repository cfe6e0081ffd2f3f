// The registration.projective stage: the colour image resampled onto the depth grid by
// the full projective mapping with lens distortion, with a status per pixel. Declared
// for tests and benchmarks, which make the stage from its descriptor.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::registration {

StageDescriptor describe_projective();

}  // namespace tilth::registration
