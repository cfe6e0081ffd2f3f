// The plausibility gates every ground estimator applies, so that no implausible number is
// ever served as valid: a colour image that carries information, a distance the rig can
// physically see, soil depths that form one surface, no soil beyond the ground measured
// on every side (soil_beyond.h), and enough confidence. A gate only
// ever invalidates a measurement (with its cause and reason); it never changes a number.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/types.hpp>

#include "soil_beyond.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/registered_color.h"
#include "tilth/param_spec.h"
#include "tilth/params.h"
#include "tilth/port_spec.h"

namespace tilth::estimation {

class PlausibilityGates {
 public:
  explicit PlausibilityGates(const Params& params);

  // The gates' parameters and optional colour input, for an estimator's descriptor.
  static std::vector<ParamSpec> params();
  static PortSpec color_port();

  // Why the registered colour in `roi` cannot tell residue from soil (mostly clipped
  // white or black, or flat), or nothing when it can; judged on every other pixel of
  // every other row.
  std::optional<std::string> unusable_color(const RegisteredColor& color, cv::Rect roi) const;

  // Invalidates a measured, valid `out` whose distance, spread or confidence is implausible.
  void check(GroundDistance& out) const;

  // What counts the soil beyond the ground of soil depths with `noise_mm` of noise
  // (depth_noise_mm; a floor up to soil_beyond_mm / 3 changes nothing): deeper by
  // soil_beyond_mm, or by three times the noise when that is more (up to three times
  // soil_beyond_mm).
  SoilBeyond soil_beyond(double noise_mm) const;
  // Invalidates a valid `out` with more than max_soil_beyond of the soil beyond it on
  // every side. The estimators apply it before check(out).
  void check_soil_beyond(GroundDistance& out, const SoilBeyond& beyond) const;
  // Whether check_soil_beyond can invalidate anything (max_soil_beyond under 1): where
  // counting the soil beyond costs a pass of its own, count it only then.
  bool checks_soil_beyond() const { return max_soil_beyond_ < 1.0; }

 private:
  double min_distance_mm_;
  double max_distance_mm_;
  double max_spread_mm_;
  double min_confidence_;
  double max_clipped_fraction_;
  double min_color_contrast_;
  double soil_beyond_mm_;
  double max_soil_beyond_;
};

}  // namespace tilth::estimation
