// Estimation: one ground distance per frame from the soil depths. One stage per file.
#include "tilth/plugin.h"

TILTH_PLUGIN("estimation")
