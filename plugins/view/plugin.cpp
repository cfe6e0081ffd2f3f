// View: what a person watches while commissioning a machine.
#include "tilth/plugin.h"

TILTH_PLUGIN("view")
