// The readers under fuzzing take file paths: this writes each input to a file of a
// scratch folder that belongs to this process (in /dev/shm when there is one, so no
// input touches the disk) and removes the folder when the process exits.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>

namespace tilth::fuzzing {

// `name` (e.g. "graph.json") in the scratch folder, holding exactly `data`.
std::filesystem::path write_input(std::string_view name, const std::uint8_t* data,
                                  std::size_t size);

}  // namespace tilth::fuzzing
