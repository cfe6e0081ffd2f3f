#include "plausibility.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>

#include "soil_region.h"
#include "tilth/error.h"

namespace tilth::estimation {
namespace {

// A channel this close to either end of 0..255 has lost what the scene looked like.
constexpr int kClippedWhite = 250;
constexpr int kClippedBlack = 5;
constexpr int kSampleStep = 2;

// Noise alone puts 0.13 % of the soil beyond three sigmas. At most three times the
// threshold: depths so noisy are no surface, and must not switch the gate off.
constexpr double kBeyondPerNoise = 3.0;
constexpr double kMaxBeyondPerThreshold = 3.0;

// What the valid colour pixels of a region show.
struct ColorEvidence {
  std::int64_t with_depth = 0;  // pixels whose colour registration could look up
  std::int64_t pixels = 0;
  std::int64_t clipped = 0;  // white or black in every channel
  // Of the channel sums (three times the gray), in integers: exact, and a short chain of
  // dependent additions per pixel.
  std::int64_t channel_sum = 0;
  std::int64_t channel_sum_squares = 0;

  double clipped_fraction() const { return static_cast<double>(clipped) / pixels; }
  double gray_deviation() const {
    const double n = static_cast<double>(pixels);
    const double mean = static_cast<double>(channel_sum) / (3 * n);
    const double mean_square = static_cast<double>(channel_sum_squares) / (9 * n);
    return std::sqrt(std::max(0.0, mean_square - mean * mean));
  }
};

std::string three_decimals(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f", value);
  return text;
}

// Every kSampleStep-th pixel of every kSampleStep-th row: the gates are fractions and a
// deviation, which a quarter of the region's tens of thousands of pixels tells as well.
ColorEvidence evidence_in(const RegisteredColor& color, cv::Rect roi) {
  ColorEvidence seen;
  for (int row = roi.y; row < roi.y + roi.height; row += kSampleStep) {
    const auto* bgr = color.bgr.ptr<cv::Vec3b>(row);
    const auto* status = color.status.ptr<std::uint8_t>(row);
    // Counted without a branch: the statuses of straw and soil alternate unpredictably.
    for (int col = roi.x; col < roi.x + roi.width; col += kSampleStep) {
      const int valid = status[col] == RegisteredColor::kValid;
      const cv::Vec3b& pixel = bgr[col];
      const int low = std::min({pixel[0], pixel[1], pixel[2]});
      const int high = std::max({pixel[0], pixel[1], pixel[2]});
      const int sum = valid * (pixel[0] + pixel[1] + pixel[2]);
      seen.with_depth += status[col] != RegisteredColor::kNoDepth;
      seen.clipped += valid & ((low >= kClippedWhite) | (high <= kClippedBlack));
      seen.channel_sum += sum;
      seen.channel_sum_squares += sum * sum;
      seen.pixels += valid;
    }
  }
  return seen;
}

}  // namespace

PlausibilityGates::PlausibilityGates(const Params& params)
    : min_distance_mm_(params.number("min_distance_mm")),
      max_distance_mm_(params.number("max_distance_mm")),
      max_spread_mm_(params.number("max_spread_mm")),
      min_confidence_(params.number("min_confidence")),
      max_clipped_fraction_(params.number("max_clipped_fraction")),
      min_color_contrast_(params.number("min_color_contrast")),
      soil_beyond_mm_(params.number("soil_beyond_mm")),
      max_soil_beyond_(params.number("max_soil_beyond")) {
  if (!(min_distance_mm_ < max_distance_mm_)) {
    throw Error("parameters 'min_distance_mm' and 'max_distance_mm': expected min < max, got " +
                one_decimal(min_distance_mm_) + " and " + one_decimal(max_distance_mm_));
  }
}

std::vector<ParamSpec> PlausibilityGates::params() {
  return {
      ParamSpec::number("min_distance_mm", 100.0)
          .range(0, std::nullopt)
          .in_unit("mm")
          .describe("a distance below this is outside what the rig can see: invalid"),
      ParamSpec::number("max_distance_mm", 2000.0)
          .range(0, std::nullopt)
          .in_unit("mm")
          .describe("a distance above this is outside what the rig can see: invalid"),
      ParamSpec::number("max_spread_mm", 30.0)
          .range(0.1, std::nullopt)
          .in_unit("mm")
          .describe("soil depths spread more than this are not one surface: invalid"),
      ParamSpec::number("soil_beyond_mm", 10.0)
          .range(0.1, std::nullopt)
          .in_unit("mm")
          .describe("soil deeper than the ground measured by more than this (or 3 times the "
                    "depth noise) lies beyond it"),
      ParamSpec::number("max_soil_beyond", 0.03)
          .range(0, 1)
          .describe("more of the soil beyond the ground on every side of the measuring point "
                    "(each quadrant) is residue taken for soil: invalid; 1 = no check"),
      ParamSpec::number("min_confidence", 0.02)
          .range(0, 1)
          .describe("a measurement trusted less than this is invalid"),
      ParamSpec::number("max_clipped_fraction", 0.5)
          .range(0, 1)
          .describe("input 'color': more of the roi clipped white or black is unusable colour"),
      ParamSpec::number("min_color_contrast", 2.0)
          .range(0, 255)
          .describe("input 'color': a flatter roi (std. dev. of gray, 0..255) is unusable colour"),
  };
}

PortSpec PlausibilityGates::color_port() {
  return PortSpec::of<RegisteredColor>("color", "the registered colour, checked for information")
      .optional();
}

std::optional<std::string> PlausibilityGates::unusable_color(const RegisteredColor& color,
                                                             cv::Rect roi) const {
  if (color.bgr.type() != CV_8UC3 || color.status.type() != CV_8UC1 ||
      color.bgr.size() != color.status.size()) {
    throw Error("input 'color': expected a CV_8UC3 image and a CV_8UC1 status of one size");
  }
  roi &= cv::Rect(cv::Point(), color.bgr.size());
  const ColorEvidence seen = evidence_in(color, roi);
  // Without depth there is no soil either: the soil count tells that, not the colour.
  if (seen.with_depth == 0) return std::nullopt;
  if (seen.pixels == 0) return "no pixel of the region of interest with depth has a colour";
  if (seen.clipped_fraction() > max_clipped_fraction_) {
    return "colour image clipped: " + one_decimal(100.0 * seen.clipped_fraction()) +
           " % of the region of interest white or black > " +
           one_decimal(100.0 * max_clipped_fraction_) + " %";
  }
  if (seen.gray_deviation() < min_color_contrast_) {
    return "colour image flat: gray deviation " + one_decimal(seen.gray_deviation()) + " < " +
           one_decimal(min_color_contrast_) + " in the region of interest";
  }
  return std::nullopt;
}

void PlausibilityGates::check(GroundDistance& out) const {
  if (!out.valid) return;
  if (out.spread_mm > max_spread_mm_) {
    out.invalidate(InvalidCause::kNotOneSurface,
                   "soil depths spread too widely: " + one_decimal(out.spread_mm) + " mm > " +
                       one_decimal(max_spread_mm_) + " mm (not one surface?)");
  } else if (!(out.distance_mm >= min_distance_mm_ && out.distance_mm <= max_distance_mm_)) {
    out.invalidate(InvalidCause::kOutOfRange, "distance " + one_decimal(out.distance_mm) +
                                                  " mm outside the rig's range " +
                                                  one_decimal(min_distance_mm_) + ".." +
                                                  one_decimal(max_distance_mm_) + " mm");
  } else if (out.confidence < min_confidence_) {
    out.invalidate(InvalidCause::kLowConfidence, "confidence " + three_decimals(out.confidence) +
                                                     " < " + three_decimals(min_confidence_));
  }
}

SoilBeyond PlausibilityGates::soil_beyond(double noise_mm) const {
  return SoilBeyond(std::clamp(kBeyondPerNoise * noise_mm, soil_beyond_mm_,
                               kMaxBeyondPerThreshold * soil_beyond_mm_));
}

void PlausibilityGates::check_soil_beyond(GroundDistance& out, const SoilBeyond& beyond) const {
  if (!out.valid || !checks_soil_beyond()) return;
  const double share = beyond.least_share();
  if (share > max_soil_beyond_) {
    out.invalidate(InvalidCause::kNotOneSurface,
                   "soil beyond the ground measured on every side: " + one_decimal(100.0 * share) +
                       " % of the soil or more in each quadrant lies over " +
                       one_decimal(beyond.beyond_mm()) + " mm deeper > " +
                       one_decimal(100.0 * max_soil_beyond_) + " % (residue taken for soil?)");
  }
}

}  // namespace tilth::estimation
