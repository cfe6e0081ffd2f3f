#include "tilth/version.h"

namespace tilth {

std::string_view version() { return TILTH_VERSION; }

}  // namespace tilth
