// Registration stages: the colour image on the depth camera's pixel grid.
#include "tilth/plugin.h"

TILTH_PLUGIN("registration")
