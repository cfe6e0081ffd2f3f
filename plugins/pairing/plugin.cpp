// Pairing: lines up frames of cameras that run on their own clocks. One stage per file.
#include "tilth/plugin.h"

TILTH_PLUGIN("pairing")
