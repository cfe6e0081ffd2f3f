// Named scene presets: the paper's static cases A-E, the dynamic layered-soil platform,
// a field case, and hard cases for segmentation. Each is a recipe for a SoilScene.
#pragma once

#include <string>
#include <vector>

namespace tilth::synthetic {

struct ScenePreset {
  std::string name;
  std::string description;
  double ground_distance_mm = 518.0;  // mounting surface to the soil datum
  int stubble = 0;                    // standing stubble stalks
  double stubble_height_mm = 65.0;
  int straws = 0;          // lying straws, stacked where they cross
  bool wet_straw = false;  // dark, soil-like straw
  bool shadows = true;
  double relief_mm = 1.5;  // micro-relief amplitude of the soil
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
