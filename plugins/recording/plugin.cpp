// Recordings: replaying and writing recorded frames, so the measurement chain runs
// offline on field data and its results are reproducible.
#include "tilth/plugin.h"

TILTH_PLUGIN("recording")
