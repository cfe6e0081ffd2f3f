// The version of the binary interface between the runtime and plugins. The runtime
// refuses a plugin built against another version before calling into it.
#pragma once

#include <cstdint>

namespace tilth {

inline constexpr std::uint32_t kAbiVersion = 6;

}  // namespace tilth
