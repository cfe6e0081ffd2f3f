// What the ground estimators share besides their region of interest (libs/roi): when it
// shows too little soil to measure, how far a measurement can be trusted, and the
// declarations of the parameters for these.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include "roi/region_of_interest.h"
#include "tilth/param_spec.h"
#include "tilth/params.h"

namespace tilth::estimation {

struct SoilRequirement {
  double min_fraction = 0.0;
  std::int64_t min_pixels = 0;

  // Empty when enough soil is visible; otherwise why not, e.g. "too little visible soil:
  // 3.1 % of the region of interest < 5.0 %".
  std::string shortfall(std::int64_t soil_pixels, std::int64_t region_pixels) const;
};

// In 0..1; docs/estimation.md explains the formula.
double confidence(double soil_fraction, double spread_mm);

std::int64_t count_finite(const cv::Mat& depth_mm, const cv::Rect& region);

// "12.3" -- one decimal, for reasons and log lines.
std::string one_decimal(double value);

ParamSpec min_soil_fraction_param();
ParamSpec min_soil_pixels_param();
SoilRequirement soil_requirement(const Params& params);

}  // namespace tilth::estimation
