// What the ground estimators share: the region of interest they read soil depths from,
// when it shows too little soil to measure, how far a measurement can be trusted, and the
// declarations of the parameters for these.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include "tilth/param_spec.h"
#include "tilth/params.h"

namespace tilth::estimation {

// The `roi` parameter: null for the middle half of the image in each direction, or
// {"x", "y", "width", "height"} in depth pixels.
class RegionOfInterest {
 public:
  // Throws tilth::Error naming the parameter when the value has another shape.
  explicit RegionOfInterest(const nlohmann::json& value);

  // The region on an image of `size`, clipped to it; throws tilth::Error when no pixel of
  // it lies in the image.
  cv::Rect on(cv::Size image) const;
  // Whether on(image) cuts off part of the configured region.
  bool clipped_on(cv::Size image) const;
  // "roi {...} reaches outside the 640x480 image; using x 600, y 400, 40x80"
  std::string clipping_note(cv::Size image) const;

 private:
  cv::Rect unclipped_on(cv::Size image) const;

  std::optional<cv::Rect> pixels_;  // empty: the middle half
};

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

ParamSpec roi_param();
ParamSpec min_soil_fraction_param();
ParamSpec min_soil_pixels_param();
SoilRequirement soil_requirement(const Params& params);

}  // namespace tilth::estimation
