// GigE Vision camera stages, through Aravis.
#include <arv.h>

#include "tilth/plugin.h"

TILTH_PLUGIN("aravis")

namespace {

// Aravis keeps global state (its interfaces and the devices they found) until
// arv_shutdown(). The plugin is what uses Aravis in the process, so it releases that
// state when it is unloaded; otherwise it outlives the library's code and shows as leaked.
struct AravisShutdown {
  ~AravisShutdown() { arv_shutdown(); }
} aravis_shutdown;

}  // namespace
