// The example's stage run alone with the SDK's stage harness, as a plugin's own test
// would: a frame whose pixel (313, 240) reads 1000 gray gives 22.90 mm at 0.0229 mm per
// gray, and 50.00 mm at 0.05. Exits 1 on any other value.
#include <cmath>
#include <iostream>
#include <memory>

#include "centre_range.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"
#include "tilth/testing/stage_harness.h"

TILTH_PLUGIN("example_check")

namespace {

bool check(const nlohmann::json& params, double expected_mm) {
  auto raw = std::make_shared<tilth::RawTofFrame>();
  raw->gray = cv::Mat(480, 640, CV_16UC1, cv::Scalar(0));
  raw->gray.at<std::uint16_t>(240, 313) = 1000;
  tilth::testing::TransformHarness stage(example::describe_centre_range(), params);
  const auto outputs = stage.run({raw});
  const double range_mm = outputs[0].get<example::CentreRange>().range_mm;
  std::cout << "centre range " << range_mm << " mm, expected " << expected_mm << "\n";
  return std::abs(range_mm - expected_mm) < 1e-9;
}

}  // namespace

int main() {
  const bool ok = check(nlohmann::json::object(), 22.9) && check({{"gray_to_mm", 0.05}}, 50.0);
  return ok ? 0 : 1;
}
