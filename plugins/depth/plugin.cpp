// Depth stages: raw ToF frames to depth images.
#include "tilth/plugin.h"

TILTH_PLUGIN("depth")
