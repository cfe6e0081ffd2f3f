// Named scene presets: the paper's static cases A-E, the dynamic layered-soil platform,
// a field case, and the hard conditions a field brings (shadows of a low sun, heavy and
// weathered cover, tilted, ridged and stepped ground, tall mixed stubble). Each is a
// recipe for a SoilScene.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace tilth::synthetic {

struct ScenePreset {
  std::string name;
  std::string description;
  double ground_distance_mm = 518.0;  // mounting surface to the soil datum
  int stubble = 0;                    // standing stubble stalks
  double stubble_height_mm = 65.0;
  double stubble_height_spread_mm = 5.0;  // heights are uniform in +-spread
  int straws = 0;                         // lying straws, stacked where they cross
  // Their sizes, uniform between the bounds: whole straws 40-250 mm long and 3-6 mm thick;
  // chaff and chopped straw are shorter and thinner.
  std::array<double, 2> straw_length_mm{40.0, 250.0};
  std::array<double, 2> straw_radius_mm{1.5, 3.0};
  bool wet_straw = false;  // dark, soil-like straw
  // Reflectances (BGR, 0..1) of the soil and of fresh straw: brown soil, beige-yellow
  // straw. Soils run from near black to pale sand, and straw bleaches towards grey.
  std::array<double, 3> soil_bgr{0.16, 0.23, 0.32};
  std::array<double, 3> straw_bgr{0.38, 0.70, 0.82};
  double weathered_fraction = 0.0;  // the first-laid (lowest) straws: dark grey, weathered
  double relief_mm = 1.5;           // micro-relief amplitude of the soil
  // Dry clay's cracks: a network of V-shaped cracks this deep (0: none) and this wide at
  // the top, around clods about crack_spacing_mm across. The truth is the clods' surface.
  double crack_mm = 0.0;
  double crack_width_mm = 8.0;
  double crack_spacing_mm = 80.0;
  // The ground's shape under the micro-relief, which the truth follows: slopes (about
  // the camera's x axis, farther towards +y when positive; about the y axis, farther
  // towards +x), and ridges and furrows (peak to peak, period, direction from +x).
  double tilt_x_deg = 0.0;
  double tilt_y_deg = 0.0;
  double ridge_mm = 0.0;
  double ridge_period_mm = 500.0;
  double ridge_angle_deg = 0.0;
  // Light: the sun's elevation and azimuth (from +x towards +y), and the sky's light in
  // shadow (BGR, relative to the sun's 1): bluish and dim in a real field.
  bool shadows = true;
  double sun_elevation_deg = 64.45;
  double sun_azimuth_deg = -37.87;
  std::array<double, 3> sky_bgr{0.45, 0.45, 0.45};
  // ToF: range noise that also grows as the surface reflects less (amplitude-limited),
  // and multipath: a range bias of this many mm per mm of residue standing nearby.
  bool reflectivity_noise = false;
  double multipath = 0.0;
  // The dynamic platform: the ground moves under the camera along x; soil layers of
  // these thicknesses lie along a track of this length.
  double track_length_mm = 0.0;
  std::vector<double> layers_mm;
  double speed_mm_per_s = 0.0;
  int frames = 20;
};

const std::vector<ScenePreset>& scene_presets();
const ScenePreset& scene_preset(const std::string& name);  // throws naming the known ones
std::vector<std::string> scene_preset_names();

}  // namespace tilth::synthetic
