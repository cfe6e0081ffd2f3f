// Fuzz target: frames.csv of an image-folder recording through read_frames_csv(). A bad
// index must end in tilth::Error naming the line; a crash, a sanitizer report or any
// other exception is a bug.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "image_folder/frames_csv.h"
#include "tilth/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = tilth::fuzzing::write_input("frames.csv", data, size);
  try {
    tilth::recording::read_frames_csv(file);
  } catch (const tilth::Error&) {
  }
  return 0;
}
