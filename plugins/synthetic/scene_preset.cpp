#include "scene_preset.h"

#include "tilth/error.h"

namespace tilth::synthetic {

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
