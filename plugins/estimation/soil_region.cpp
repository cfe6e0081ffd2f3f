#include "soil_region.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace tilth::estimation {
namespace {

// A quarter of the region showing soil is some 19 000 pixels in the default region of a
// 640x480 image: far more than the median needs, so more soil earns no more trust.
constexpr double kFullConfidenceSoilFraction = 0.25;
// Twice the ToF camera's typical accuracy (+-5 mm, Basler blaze-101): soil depths spread
// this much are rough ground or residue taken for soil, and halve the confidence.
constexpr double kHalfConfidenceSpreadMm = 10.0;

}  // namespace

std::string SoilRequirement::shortfall(std::int64_t soil_pixels, std::int64_t region_pixels) const {
  const double fraction = static_cast<double>(soil_pixels) / static_cast<double>(region_pixels);
  if (fraction < min_fraction) {
    return "too little visible soil: " + one_decimal(100.0 * fraction) +
           " % of the region of interest < " + one_decimal(100.0 * min_fraction) + " %";
  }
  if (soil_pixels < min_pixels) {
    return "too little visible soil: " + std::to_string(soil_pixels) + " px < " +
           std::to_string(min_pixels) + " px";
  }
  return "";
}

double confidence(double soil_fraction, double spread_mm) {
  const double coverage = std::min(1.0, soil_fraction / kFullConfidenceSoilFraction);
  const double relative_spread = spread_mm / kHalfConfidenceSpreadMm;
  return coverage / (1.0 + relative_spread * relative_spread);
}

std::int64_t count_finite(const cv::Mat& depth_mm, const cv::Rect& region) {
  std::int64_t count = 0;
  for (int row = region.y; row < region.y + region.height; ++row) {
    const float* depth = depth_mm.ptr<float>(row);
    for (int col = region.x; col < region.x + region.width; ++col) {
      count += depth[col] - depth[col] == 0.0f ? 1 : 0;  // false for NaN and infinities
    }
  }
  return count;
}

std::string one_decimal(double value) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << value;
  return out.str();
}

ParamSpec min_soil_fraction_param() {
  return ParamSpec::number("min_soil_fraction", 0.05)
      .range(0, 1)
      .describe("below this fraction of soil pixels in the roi the measurement is invalid");
}

ParamSpec min_soil_pixels_param() {
  return ParamSpec::integer("min_soil_pixels", 200)
      .range(1, std::nullopt)
      .in_unit("px")
      .describe("below this many soil pixels in the roi the measurement is invalid");
}

SoilRequirement soil_requirement(const Params& params) {
  return {params.number("min_soil_fraction"), params.integer("min_soil_pixels")};
}

}  // namespace tilth::estimation
