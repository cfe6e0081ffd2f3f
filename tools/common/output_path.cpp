#include "output_path.h"

#include "tilth/error.h"

namespace tilth::tools {

void check_output_path(const std::filesystem::path& output, bool overwrite) {
  namespace fs = std::filesystem;
  if (overwrite || !fs::exists(output)) return;
  if (fs::is_directory(output) && fs::is_empty(output)) return;
  throw Error(output.string() + ": exists" + (fs::is_directory(output) ? " and is not empty" : "") +
              "; use --overwrite to replace it");
}

}  // namespace tilth::tools
