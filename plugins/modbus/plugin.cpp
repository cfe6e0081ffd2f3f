// Modbus: the ground distance to the machine's PLC over Modbus TCP.
#include "tilth/plugin.h"

TILTH_PLUGIN("modbus")
