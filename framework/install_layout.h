// Where Tilth finds what it ships: relative to the running executable, so that the build
// tree and an installed tree (bin/, lib/tilth/plugins/, share/tilth/) work alike and no
// binary names a source or build path.
#pragma once

#include <filesystem>

namespace tilth {

// The directory of the running executable (/proc/self/exe).
std::filesystem::path executable_dir();

// The plugins shipped with this executable: <prefix>/lib/tilth/plugins.
std::filesystem::path shipped_plugin_dir();

// The graphs and calibrations shipped with this executable: <prefix>/share/tilth, holding
// graphs/ and calib/.
std::filesystem::path shipped_data_dir();

}  // namespace tilth
