#include "preset_changes.h"

#include <algorithm>
#include <array>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "tilth/error.h"

namespace tilth::synthetic {
namespace {

using Setter = std::function<void(ScenePreset&, const nlohmann::json&)>;

struct Field {
  std::string name;
  Setter set;
};

std::string shortened(const std::string& text) {
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}

std::string shown(const nlohmann::json& value) { return shortened(value.dump()); }

[[noreturn]] void reject(const std::string& field, const std::string& expected,
                         const nlohmann::json& value) {
  throw Error("parameter 'scene': field '" + field + "': expected " + expected + ", got " +
              shown(value));
}

std::string number_text(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

std::string range_text(double low, double high) {
  return "from " + number_text(low) + " to " + number_text(high);
}

double in_range(const std::string& field, const nlohmann::json& value, double low, double high,
                const std::string& what) {
  if (!value.is_number() || !(value.get<double>() >= low && value.get<double>() <= high)) {
    reject(field, what + " " + range_text(low, high), value);
  }
  return value.get<double>();
}

Field number(std::string name, double ScenePreset::*member, double low, double high) {
  return {name, [name, member, low, high](ScenePreset& preset, const nlohmann::json& value) {
            preset.*member = in_range(name, value, low, high, "a number");
          }};
}

Field integer(std::string name, int ScenePreset::*member, int high) {
  return {name, [name, member, high](ScenePreset& preset, const nlohmann::json& value) {
            if (!value.is_number_integer())
              reject(name, "an integer " + range_text(0, high), value);
            preset.*member = static_cast<int>(in_range(name, value, 0, high, "an integer"));
          }};
}

Field boolean(std::string name, bool ScenePreset::*member) {
  return {name, [name, member](ScenePreset& preset, const nlohmann::json& value) {
            if (!value.is_boolean()) reject(name, "true or false", value);
            preset.*member = value.get<bool>();
          }};
}

template <std::size_t N>
Field numbers(std::string name, std::array<double, N> ScenePreset::*member, double low, double high,
              bool ascending) {
  return {name,
          [name, member, low, high, ascending](ScenePreset& preset, const nlohmann::json& value) {
            const std::string what = "[" + std::to_string(N) + " numbers" +
                                     (ascending ? ", the first not above the second" : "") +
                                     "] each " + range_text(low, high);
            if (!value.is_array() || value.size() != N) reject(name, what, value);
            std::array<double, N> parsed{};
            for (std::size_t i = 0; i < N; ++i) {
              if (!value[i].is_number() ||
                  !(value[i].get<double>() >= low && value[i].get<double>() <= high)) {
                reject(name, what, value);
              }
              parsed[i] = value[i].get<double>();
            }
            if (ascending && parsed.front() > parsed.back()) reject(name, what, value);
            preset.*member = parsed;
          }};
}

Field list(std::string name, std::vector<double> ScenePreset::*member, double low, double high) {
  return {name, [name, member, low, high](ScenePreset& preset, const nlohmann::json& value) {
            const std::string what = "an array of numbers each " + range_text(low, high);
            if (!value.is_array()) reject(name, what, value);
            std::vector<double> parsed;
            for (const auto& item : value) {
              if (!item.is_number() || !(item.get<double>() >= low && item.get<double>() <= high)) {
                reject(name, what, value);
              }
              parsed.push_back(item.get<double>());
            }
            preset.*member = std::move(parsed);
          }};
}

// Every field but the name, the description and the frame count (the stage's `frames`).
const std::vector<Field>& fields() {
  using P = ScenePreset;
  static const std::vector<Field> known = {
      number("ground_distance_mm", &P::ground_distance_mm, 50, 5000),
      integer("stubble", &P::stubble, 20000),
      number("stubble_height_mm", &P::stubble_height_mm, 0, 1000),
      number("stubble_height_spread_mm", &P::stubble_height_spread_mm, 0, 1000),
      integer("straws", &P::straws, 50000),
      numbers("straw_length_mm", &P::straw_length_mm, 1, 2000, true),
      numbers("straw_radius_mm", &P::straw_radius_mm, 0.1, 50, true),
      boolean("wet_straw", &P::wet_straw),
      numbers("soil_bgr", &P::soil_bgr, 0, 1, false),
      numbers("straw_bgr", &P::straw_bgr, 0, 1, false),
      number("weathered_fraction", &P::weathered_fraction, 0, 1),
      number("relief_mm", &P::relief_mm, 0, 100),
      number("crack_mm", &P::crack_mm, 0, 200),
      number("crack_width_mm", &P::crack_width_mm, 0.5, 200),
      number("crack_spacing_mm", &P::crack_spacing_mm, 10, 2000),
      number("tilt_x_deg", &P::tilt_x_deg, -30, 30),
      number("tilt_y_deg", &P::tilt_y_deg, -30, 30),
      number("ridge_mm", &P::ridge_mm, 0, 500),
      number("ridge_period_mm", &P::ridge_period_mm, 10, 10000),
      number("ridge_angle_deg", &P::ridge_angle_deg, -360, 360),
      boolean("shadows", &P::shadows),
      number("sun_elevation_deg", &P::sun_elevation_deg, 1, 90),
      number("sun_azimuth_deg", &P::sun_azimuth_deg, -360, 360),
      numbers("sky_bgr", &P::sky_bgr, 0, 1, false),
      boolean("reflectivity_noise", &P::reflectivity_noise),
      number("multipath", &P::multipath, 0, 1),
      number("track_length_mm", &P::track_length_mm, 0, 100000),
      list("layers_mm", &P::layers_mm, -500, 500),
      number("speed_mm_per_s", &P::speed_mm_per_s, -10000, 10000),
  };
  return known;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::vector<std::string> field_names() {
  std::vector<std::string> names;
  for (const auto& field : fields()) names.push_back(field.name);
  return names;
}

}  // namespace

ScenePreset changed_preset(ScenePreset preset, const nlohmann::json& changes) {
  if (changes.is_null()) return preset;
  if (changes.is_string()) {
    throw Error(
        "parameter 'scene': expected a JSON object of preset fields such as {\"straws\": 600}, "
        "got the text '" +
        shortened(changes.get<std::string>()) + "'");
  }
  if (!changes.is_object()) {
    throw Error("parameter 'scene': expected an object of preset fields, got " + shown(changes));
  }
  for (const auto& [name, value] : changes.items()) {
    const auto& known = fields();
    const auto field =
        std::find_if(known.begin(), known.end(), [&](const Field& f) { return f.name == name; });
    if (field == known.end()) {
      throw Error("parameter 'scene': no preset field '" + name + "'; the fields are " +
                  joined(field_names()));
    }
    field->set(preset, value);
  }
  if (preset.stubble_height_spread_mm > preset.stubble_height_mm) {
    throw Error("parameter 'scene': stubble_height_spread_mm (" +
                number_text(preset.stubble_height_spread_mm) +
                ") is more than stubble_height_mm (" + number_text(preset.stubble_height_mm) +
                "): stalks would grow below the soil");
  }
  if ((!preset.layers_mm.empty() || preset.speed_mm_per_s != 0.0) &&
      preset.track_length_mm <= 0.0) {
    throw Error(
        "parameter 'scene': layers_mm and speed_mm_per_s need a track (track_length_mm > 0)");
  }
  return preset;
}

}  // namespace tilth::synthetic
