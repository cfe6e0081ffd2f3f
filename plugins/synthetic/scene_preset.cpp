#include "scene_preset.h"

#include "tilth/error.h"

namespace tilth::synthetic {
namespace {

// What the sun and the camera of a real field add to a preset: a dimmer, bluish sky in
// the shadows, ToF noise that grows on dark surfaces, and multipath near standing residue.
ScenePreset in_the_field(ScenePreset preset, double sun_elevation_deg) {
  preset.sun_elevation_deg = sun_elevation_deg;
  preset.sky_bgr = {0.42, 0.34, 0.27};
  preset.reflectivity_noise = true;
  preset.multipath = 0.02;
  return preset;
}

// The conditions the paper's cases lack, each alone on top of a paper-like scene (`base`:
// case A's stubble on undisturbed soil), so a scenario that fails names its cause.
void add_field_conditions(std::vector<ScenePreset>& list, const ScenePreset& base) {
  ScenePreset low_sun = in_the_field(base, 25.0);
  low_sun.name = "low_sun";
  low_sun.description =
      "a sun 25 degrees high: long, bluish shadows of stubble and 300 straws on soil and on "
      "lower straw, 518 mm";
  low_sun.straws = 300;
  list.push_back(low_sun);

  ScenePreset heavy = in_the_field(base, 35.0);
  heavy.name = "heavy_cover";
  heavy.description =
      "about 85 % cover: 500 straws, the lower half weathered dark grey, shadows, 518 mm";
  heavy.straws = 500;
  heavy.weathered_fraction = 0.5;
  list.push_back(heavy);

  ScenePreset bleached = heavy;
  bleached.name = "bleached_cover";
  bleached.description =
      "heavy_cover with sun-bleached straw, pale and nearly grey: its colour barely differs "
      "from the soil's, 518 mm";
  bleached.straw_bgr = {0.58, 0.74, 0.80};
  list.push_back(bleached);

  ScenePreset light_soil = in_the_field(base, 45.0);
  light_soil.name = "light_soil";
  light_soil.description = "pale, sandy soil under 150 straws, 518 mm";
  light_soil.straws = 150;
  light_soil.soil_bgr = {0.30, 0.42, 0.52};
  list.push_back(light_soil);

  ScenePreset chaff = in_the_field(base, 45.0);
  chaff.name = "chaff";
  chaff.description =
      "case A's stubble and 5000 pieces of chaff and chopped straw, 10-40 mm long and 1-2 mm "
      "thick: residue lower than the height cue sees, 518 mm";
  chaff.straws = 5000;
  chaff.straw_length_mm = {10.0, 40.0};
  chaff.straw_radius_mm = {0.5, 1.0};
  list.push_back(chaff);

  ScenePreset bleached_chaff = chaff;
  bleached_chaff.name = "bleached_chaff";
  bleached_chaff.description = "chaff, sun-bleached: pale, nearly grey and lying flat, 518 mm";
  bleached_chaff.straw_bgr = bleached.straw_bgr;
  list.push_back(bleached_chaff);

  ScenePreset tilted = in_the_field(base, 45.0);
  tilted.name = "tilted";
  tilted.description = "ground sloping 3 degrees down towards the image bottom, 150 straws, 585 mm";
  tilted.ground_distance_mm = 585.0;
  tilted.tilt_x_deg = 3.0;
  tilted.straws = 150;
  list.push_back(tilted);

  ScenePreset tilted_5 = tilted;
  tilted_5.name = "tilted_5";
  tilted_5.description = "ground tilted 5 degrees and rolled -5 degrees, 150 straws, 585 mm";
  tilted_5.tilt_y_deg = -5.0;
  tilted_5.tilt_x_deg = 5.0;
  list.push_back(tilted_5);

  ScenePreset ridges = in_the_field(base, 45.0);
  ridges.name = "ridges";
  ridges.description =
      "ridges and furrows 20 mm high every 600 mm crossing the region, 150 straws, 518 mm";
  ridges.ridge_mm = 20.0;
  ridges.ridge_period_mm = 600.0;
  ridges.ridge_angle_deg = 70.0;
  ridges.straws = 150;
  list.push_back(ridges);

  ScenePreset cracked = in_the_field(base, 45.0);
  cracked.name = "cracked";
  cracked.description =
      "dry clay: cracks 10-20 mm deep and 8 mm wide around clods about 80 mm across, 150 "
      "straws, 518 mm";
  cracked.crack_mm = 20.0;
  cracked.crack_width_mm = 8.0;
  cracked.crack_spacing_mm = 80.0;
  cracked.straws = 150;
  list.push_back(cracked);

  ScenePreset cracked_cover = heavy;
  cracked_cover.name = "cracked_cover";
  cracked_cover.description = "heavy_cover on cracked clay (the cracks of cracked), 518 mm";
  cracked_cover.crack_mm = cracked.crack_mm;
  cracked_cover.crack_width_mm = cracked.crack_width_mm;
  cracked_cover.crack_spacing_mm = cracked.crack_spacing_mm;
  list.push_back(cracked_cover);

  ScenePreset stubble = in_the_field(base, 40.0);
  stubble.name = "tall_stubble";
  stubble.description =
      "300 stalks 30-150 mm high with their shadows and multipath, 100 straws, 518 mm";
  stubble.stubble = 300;
  stubble.stubble_height_mm = 90.0;
  stubble.stubble_height_spread_mm = 60.0;
  stubble.multipath = 0.03;
  stubble.straws = 100;
  list.push_back(stubble);

  ScenePreset steps = in_the_field(base, 45.0);
  steps.name = "steps";
  steps.description =
      "moving ground: a 1600 mm track of soil steps 2-12 mm high every 200 mm, with stubble "
      "and straw, 518 mm";
  steps.stubble = 40;
  steps.straws = 400;
  steps.relief_mm = 1.0;
  steps.track_length_mm = 1600.0;
  steps.layers_mm = {0.0, 4.0, 9.0, 3.0, -2.0, 6.0, 12.0, 5.0};
  steps.speed_mm_per_s = 400.0;
  steps.frames = 120;
  list.push_back(steps);
}

}  // namespace

const std::vector<ScenePreset>& scene_presets() {
  // Static cases follow the paper's section 3.1: 518 mm, stubble 60-70 mm high, then
  // more and more straw on undisturbed soil.
  static const std::vector<ScenePreset> presets = [] {
    std::vector<ScenePreset> list;
    ScenePreset flat;
    flat.name = "flat";
    flat.description = "flat bare soil without relief or residue, 518 mm";
    flat.relief_mm = 0.0;
    list.push_back(flat);
    ScenePreset a;
    a.name = "case_a";
    a.description = "paper case A: soil with standing wheat stubble only, 518 mm";
    a.stubble = 60;
    list.push_back(a);
    const int straws[] = {60, 150, 300, 450};
    const char* names[] = {"case_b", "case_c", "case_d", "case_e"};
    for (int i = 0; i < 4; ++i) {
      ScenePreset c = a;
      c.name = names[i];
      c.straws = straws[i];
      c.description = "paper case " + std::string(1, static_cast<char>('B' + i)) +
                      ": stubble and " + std::to_string(straws[i]) + " lying straws, 518 mm";
      list.push_back(c);
    }
    ScenePreset covered = a;
    covered.name = "covered";
    covered.description = "soil fully covered by straw: no valid measurement is possible";
    covered.straws = 4000;
    list.push_back(covered);
    ScenePreset wet = a;
    wet.name = "wet_straw";
    wet.description = "dark, wet straw whose colour is close to the soil's, 518 mm";
    wet.straws = 150;
    wet.wet_straw = true;
    list.push_back(wet);
    ScenePreset shadows = a;
    shadows.name = "shadows";
    shadows.description =
        "dense stubble 120 mm high and 150 straws: long shadows over soil and straw, 518 mm";
    shadows.stubble = 400;
    shadows.stubble_height_mm = 120.0;
    shadows.straws = 150;
    list.push_back(shadows);
    ScenePreset mat = a;
    mat.name = "covered_mat";
    mat.description =
        "1000 straws piled up to 250 mm: under 2 % of the soil visible, with depth and colour";
    mat.straws = 1000;
    list.push_back(mat);
    ScenePreset wet_mat = mat;
    wet_mat.name = "covered_wet";
    wet_mat.description = "covered_mat with dark, wet straw: soil-coloured residue over it all";
    wet_mat.wet_straw = true;
    list.push_back(wet_mat);
    ScenePreset layered;
    layered.name = "layered";
    layered.description =
        "dynamic platform: camera 455 mm above a 4000 mm track with 20/40/60/80 mm soil layers";
    layered.ground_distance_mm = 455.0;
    layered.relief_mm = 1.0;
    layered.straws = 0;
    layered.track_length_mm = 4000.0;
    layered.layers_mm = {0.0, 20.0, 40.0, 60.0, 80.0};
    layered.speed_mm_per_s = 400.0;
    layered.frames = 300;
    list.push_back(layered);
    ScenePreset field;
    field.name = "field";
    field.description = "field: rough soil, stubble and straw, 585 mm";
    field.ground_distance_mm = 585.0;
    field.relief_mm = 4.0;
    field.stubble = 40;
    field.straws = 250;
    list.push_back(field);
    add_field_conditions(list, a);
    return list;
  }();
  return presets;
}

std::vector<std::string> scene_preset_names() {
  std::vector<std::string> names;
  for (const auto& preset : scene_presets()) names.push_back(preset.name);
  return names;
}

const ScenePreset& scene_preset(const std::string& name) {
  for (const auto& preset : scene_presets()) {
    if (preset.name == name) return preset;
  }
  std::string known;
  for (const auto& preset : scene_presets()) known += (known.empty() ? "" : ", ") + preset.name;
  throw Error("unknown scene preset '" + name + "' (known: " + known + ")");
}

}  // namespace tilth::synthetic
