// Synthetic sources: frames computed from a closed-form scene, for demos and tests
// that need no camera and no recording.
#include "tilth/plugin.h"

TILTH_PLUGIN("synthetic")
