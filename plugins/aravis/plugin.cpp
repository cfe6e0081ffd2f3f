// GigE Vision camera stages, through Aravis.
#include "tilth/plugin.h"

TILTH_PLUGIN("aravis")
