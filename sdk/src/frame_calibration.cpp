#include "tilth/frame_calibration.h"

namespace tilth {

ParamSpec frame_calibration_param() {
  return ParamSpec::path("calibration", "")
      .describe(
          "rig calibration file overriding the frames' own (a recording's, or the "
          "camera source's); \"\" = the frames' own");
}

std::string calibration_differences(const RigCalibration& a, const RigCalibration& b) {
  const nlohmann::json here = to_json(a);
  const nlohmann::json there = to_json(b);
  std::string differences;
  for (const auto& change : nlohmann::json::diff(here, there)) {
    const nlohmann::json::json_pointer where(change.at("path").get<std::string>());
    if (!differences.empty()) differences += "; ";
    differences += where.to_string() + ": " + (here.contains(where) ? here[where].dump() : "-") +
                   " against " + (there.contains(where) ? there[where].dump() : "-");
  }
  return differences;
}

}  // namespace tilth
