#include "framework/install_layout.h"

#include "tilth/error.h"

namespace tilth {

namespace fs = std::filesystem;

fs::path executable_dir() {
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (error) {
    throw Error("cannot read /proc/self/exe to find the files shipped with Tilth: " +
                error.message());
  }
  return self.parent_path();
}

fs::path shipped_plugin_dir() {
  return (executable_dir() / TILTH_PLUGIN_DIR_FROM_BIN).lexically_normal();
}

fs::path shipped_data_dir() {
  return (executable_dir() / TILTH_DATA_DIR_FROM_BIN).lexically_normal();
}

}  // namespace tilth
