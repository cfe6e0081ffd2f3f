// A scene made from a preset with some of its fields changed, from a JSON object such as
// {"straws": 600, "soil_bgr": [0.2, 0.25, 0.3]}: any scene the simulator can render, not
// only the named ones (synthetic.scene's `scene` parameter, `tilth simulate --scene`).
#pragma once

#include <nlohmann/json.hpp>

#include "scene_preset.h"

namespace tilth::synthetic {

// `preset` with every field `changes` names set to its value. Throws tilth::Error naming
// the field, what it expected and what it got, and the fields known when a name is not one.
ScenePreset changed_preset(ScenePreset preset, const nlohmann::json& changes);

}  // namespace tilth::synthetic
