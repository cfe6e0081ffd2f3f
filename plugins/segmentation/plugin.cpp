// Segmentation: which depth pixels show soil. One stage per file.
#include "tilth/plugin.h"

TILTH_PLUGIN("segmentation")
