// A camera's GenICam features by name: set from JSON values and read back, with errors
// that name the feature and the camera; and the listing `tilth cameras --features` prints.
#pragma once

#include <string>
#include <vector>

#include <arv.h>
#include <nlohmann/json.hpp>

#include "tilth/error.h"

namespace tilth::aravis {

struct FeatureSetting {
  std::string name;
  nlohmann::json value;
};

// The `features` parameter as settings in the order they apply: an object, in the order
// its keys arrive, or an array of one-member objects ([{"TriggerSelector": "FrameStart"},
// {"TriggerMode": "On"}]) when the order matters. Throws tilth::Error on any other shape.
template <class Json>
std::vector<FeatureSetting> parse_feature_settings(const Json& features) {
  std::vector<FeatureSetting> settings;
  auto add_members = [&settings](const Json& object) {
    for (const auto& [name, value] : object.items()) {
      settings.push_back({name, nlohmann::json(value)});
    }
  };
  if (features.is_object()) {
    add_members(features);
  } else if (features.is_array()) {
    for (std::size_t i = 0; i < features.size(); ++i) {
      if (!features[i].is_object() || features[i].size() != 1) {
        throw Error("parameter 'features': entry " + std::to_string(i) +
                    " must be an object with one member {\"FeatureName\": value}, got " +
                    features[i].dump());
      }
      add_members(features[i]);
    }
  } else if (!features.is_null()) {
    throw Error(
        "parameter 'features': expected an object {\"FeatureName\": value, ...} or an array "
        "of one-member objects, got " +
        features.dump());
  }
  return settings;
}

class CameraFeatures {
 public:
  // `device` must outlive this object; `camera` names the camera in error messages.
  CameraFeatures(ArvDevice* device, std::string camera);

  // The feature exists, is implemented and is available in the current configuration.
  bool available(const std::string& name) const;
  // Sets `name` according to its GenICam type (enumeration: entry name or value; boolean;
  // integer; float; string; command: true executes it) and returns the value read back.
  std::string set(const std::string& name, const nlohmann::json& value);
  std::string read(const std::string& name) const;
  double read_number(const std::string& name) const;  // an integer or float feature

 private:
  ArvGcFeatureNode* node(const std::string& name) const;
  std::string where(const std::string& name) const;

  ArvDevice* device_;
  std::string camera_;
};

struct FeatureRow {
  int depth = 0;  // nesting of categories, 0 = the root's members
  bool category = false;
  std::string name;
  std::string type;    // the GenICam node type: Integer, IntReg, Float, Enumeration, ...
  std::string value;   // empty for categories and commands; "(unreadable: ...)" on error
  std::string access;  // RO, RW, WO; "NA" when not available now
};

// Every feature reachable from the camera's Root category, depth first, in the order
// of its description file.
std::vector<FeatureRow> list_features(ArvDevice* device);

}  // namespace tilth::aravis
