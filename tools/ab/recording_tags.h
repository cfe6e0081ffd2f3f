// Tags of recordings (site, crop, machine, ...) from a CSV file given with --tags: a
// header `recording,KEY...` and a line per recording, named as tilth ab names it.
#pragma once

#include <filesystem>
#include <vector>

#include "recording_list.h"

namespace tilth::ab {

// Sets the tags the file gives, over those the recordings had. Throws tilth::Error naming
// the file and line of a malformed line or of a recording that is not among those given.
void apply_tags_file(const std::filesystem::path& file, std::vector<Recording>& recordings);

}  // namespace tilth::ab
