// What a tool checks before it writes a recording: an existing output is replaced only
// when the user said --overwrite.
#pragma once

#include <filesystem>

namespace tilth::tools {

// Throws tilth::Error when `output` is a file or a non-empty folder and `overwrite` is
// false.
void check_output_path(const std::filesystem::path& output, bool overwrite);

}  // namespace tilth::tools
