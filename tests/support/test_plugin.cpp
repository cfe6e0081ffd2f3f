// The stage list of a test or benchmark that links stage object libraries (tilth_NAME_stages)
// instead of loading their plugins: one list, so that several families can be linked.
#include "tilth/plugin.h"

TILTH_PLUGIN("tests")
