// Sinks: where measurements leave the graph.
#include "tilth/plugin.h"

TILTH_PLUGIN("sinks")
