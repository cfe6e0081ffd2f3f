#include "soil_region.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "tilth/error.h"

namespace tilth::estimation {
namespace {

constexpr std::array<const char*, 4> kRoiFields = {"x", "y", "width", "height"};

// A quarter of the region showing soil is some 19 000 pixels in the default region of a
// 640x480 image: far more than the median needs, so more soil earns no more trust.
constexpr double kFullConfidenceSoilFraction = 0.25;
// Twice the ToF camera's typical accuracy (+-5 mm, Basler blaze-101): soil depths spread
// this much are rough ground or residue taken for soil, and halve the confidence.
constexpr double kHalfConfidenceSpreadMm = 10.0;

[[noreturn]] void roi_error(const std::string& problem) {
  throw Error("parameter 'roi': " + problem);
}

std::string size_text(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

std::optional<cv::Rect> parse_roi(const nlohmann::json& value) {
  if (value.is_null()) return std::nullopt;
  if (!value.is_object()) {
    roi_error(
        "expected null (the middle half of the image) or {\"x\", \"y\", \"width\", \"height\"} "
        "in pixels, got " +
        value.dump());
  }
  for (const auto& [name, field] : value.items()) {
    if (std::find(kRoiFields.begin(), kRoiFields.end(), name) == kRoiFields.end()) {
      roi_error("no field \"" + name + "\" (expected x, y, width, height)");
    }
  }
  std::array<int, 4> numbers{};
  for (std::size_t i = 0; i < kRoiFields.size(); ++i) {
    const std::string name = kRoiFields[i];
    if (!value.contains(name)) roi_error("missing field \"" + name + "\"");
    const nlohmann::json& field = value.at(name);
    if (!field.is_number_integer()) {
      roi_error("\"" + name + "\" must be an integer number of pixels, got " + field.dump());
    }
    numbers[i] = field.get<int>();
  }
  const cv::Rect rect(numbers[0], numbers[1], numbers[2], numbers[3]);
  if (rect.width < 1) roi_error("\"width\" must be >= 1 px, got " + std::to_string(rect.width));
  if (rect.height < 1) roi_error("\"height\" must be >= 1 px, got " + std::to_string(rect.height));
  return rect;
}

}  // namespace

RegionOfInterest::RegionOfInterest(const nlohmann::json& value) : pixels_(parse_roi(value)) {}

cv::Rect RegionOfInterest::unclipped_on(cv::Size image) const {
  if (pixels_) return *pixels_;
  const cv::Size half(std::max(1, image.width / 2), std::max(1, image.height / 2));
  return {(image.width - half.width) / 2, (image.height - half.height) / 2, half.width,
          half.height};
}

cv::Rect RegionOfInterest::on(cv::Size image) const {
  const cv::Rect wanted = unclipped_on(image);
  const cv::Rect region = wanted & cv::Rect({0, 0}, image);
  if (region.empty()) {
    roi_error("x " + std::to_string(wanted.x) + ", y " + std::to_string(wanted.y) + ", " +
              size_text(wanted.size()) + " lies outside the " + size_text(image) + " depth image");
  }
  return region;
}

bool RegionOfInterest::clipped_on(cv::Size image) const { return on(image) != unclipped_on(image); }

std::string RegionOfInterest::clipping_note(cv::Size image) const {
  const cv::Rect wanted = unclipped_on(image);
  const cv::Rect used = on(image);
  return "roi x " + std::to_string(wanted.x) + ", y " + std::to_string(wanted.y) + ", " +
         size_text(wanted.size()) + " reaches outside the " + size_text(image) +
         " image; using x " + std::to_string(used.x) + ", y " + std::to_string(used.y) + ", " +
         size_text(used.size());
}

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
      count += std::isfinite(depth[col]) ? 1 : 0;
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

ParamSpec roi_param() {
  return ParamSpec::json("roi", nullptr)
      .in_unit("px")
      .describe(
          "region of interest {\"x\", \"y\", \"width\", \"height\"}, clipped to the image; "
          "null = the middle half in each direction");
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
