// Fuzz target: a calibration file through load_calibration(). A bad file must end in
// tilth::Error; one that loads must survive the round trip `tilth calibrate` makes
// (to_json, then parse_calibration again) unchanged.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "fuzz_input_file.h"
#include "tilth/calibration.h"
#include "tilth/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto file = tilth::fuzzing::write_input("rig.calib.json", data, size);
  tilth::RigCalibration loaded;
  try {
    loaded = tilth::load_calibration(file);
  } catch (const tilth::Error&) {
    return 0;
  }
  const nlohmann::json written = tilth::to_json(loaded);
  try {
    if (tilth::to_json(tilth::parse_calibration(written, "round trip")) != written) {
      std::fprintf(stderr, "calibration changed in a round trip:\n%s\n", written.dump(2).c_str());
      std::abort();
    }
  } catch (const tilth::Error& error) {
    std::fprintf(stderr, "a loaded calibration does not load again: %s\n", error.what());
    std::abort();
  }
  return 0;
}
