// MCAP recordings: recording and replaying frames in the MCAP container, which Foxglove
// opens as it is and which survives a process killed mid-write.
#include "tilth/plugin.h"

TILTH_PLUGIN("mcap")
