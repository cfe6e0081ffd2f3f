// The stage list that the stages of the plugins a fuzz target links register in.
#include "tilth/plugin.h"

TILTH_PLUGIN("fuzz")
