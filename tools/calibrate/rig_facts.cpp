#include "rig_facts.h"

#include <optional>

#include "number_pair.h"
#include "tilth/error.h"

namespace tilth::calibrate {
namespace {

// "640x480" -> {640, 480}.
std::optional<std::pair<int, int>> parse_size(const std::string& text) {
  const auto size = number_pair<int>(text, 'x');
  if (!size || size->first <= 0 || size->second <= 0) return std::nullopt;
  return size;
}

void apply_size(const cli::CommandLine& line, const std::string& option, CameraIntrinsics& camera) {
  const auto text = line.value(option);
  if (!text) return;
  const auto size = parse_size(*text);
  if (!size)
    throw Error(option + ": expected WIDTHxHEIGHT in pixels, e.g. 640x480, got '" + *text + "'");
  camera.width = size->first;
  camera.height = size->second;
}

[[noreturn]] void missing(const std::string& what) {
  throw Error("missing " + what + ": give it, or --base RIG.calib.json whose value is kept");
}

}  // namespace

RigCalibration rig_facts(const cli::CommandLine& line, bool need_sizes) {
  const auto base = line.value("--base");
  RigCalibration rig = base ? load_calibration(*base) : RigCalibration{};
  if (const auto model = line.value("--depth-model")) rig.depth.model = *model;
  if (const auto model = line.value("--color-model")) rig.color.model = *model;
  if (const auto measure = line.value("--depth-measure")) {
    if (*measure == "radial") {
      rig.depth.depth_measure = DepthMeasure::kRadial;
    } else if (*measure == "z") {
      rig.depth.depth_measure = DepthMeasure::kZ;
    } else {
      throw Error("--depth-measure: expected radial or z, got '" + *measure + "'");
    }
  }
  // The bounds of docs/formats/calibration.md; the written file is validated in full.
  if (const auto value = line.real("--gray-to-mm", 1e-9, 2.0)) rig.depth.gray_to_mm = *value;
  if (const auto value = line.real("--gray-offset-mm", -200.0, 200.0)) {
    rig.depth.gray_offset_mm = *value;
  }
  if (const auto value = line.real("--z-offset-mm", -200.0, 200.0)) rig.depth.z_offset_mm = *value;
  apply_size(line, "--depth-size", rig.depth);
  apply_size(line, "--color-size", rig.color);
  if (base) return rig;
  if (!line.value("--gray-to-mm")) missing("--gray-to-mm (the ToF camera's Scan3dCoordinateScale)");
  if (!line.value("--z-offset-mm")) {
    missing("--z-offset-mm (the ToF optical centre behind the mounting surface)");
  }
  if (need_sizes && !line.value("--depth-size")) missing("--depth-size WIDTHxHEIGHT");
  if (need_sizes && !line.value("--color-size")) missing("--color-size WIDTHxHEIGHT");
  return rig;
}

}  // namespace tilth::calibrate
