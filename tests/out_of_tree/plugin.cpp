// The example plugin's one symbol; its stages register themselves (TILTH_STAGE).
#include "tilth/plugin.h"

TILTH_PLUGIN("example")
