#include "camera_features.h"

#include <cmath>
#include <functional>

#include "aravis/gobject_ptr.h"

namespace tilth::aravis {
namespace {

std::string node_type(ArvGcFeatureNode* node) {
  return arv_dom_node_get_node_name(ARV_DOM_NODE(node));
}

std::string access_text(ArvGcFeatureNode* node) {
  if (!arv_gc_feature_node_is_available(node, nullptr)) return "NA";
  switch (arv_gc_feature_node_get_actual_access_mode(node)) {
    case ARV_GC_ACCESS_MODE_RO:
      return "RO";
    case ARV_GC_ACCESS_MODE_WO:
      return "WO";
    case ARV_GC_ACCESS_MODE_RW:
      return "RW";
    default:
      return "?";
  }
}

std::string enumeration_entries(ArvGcEnumeration* enumeration) {
  guint count = 0;
  const char** entries =
      arv_gc_enumeration_dup_available_string_values(enumeration, &count, nullptr);
  std::string text;
  for (guint i = 0; i < count; ++i) text += std::string(i == 0 ? "" : ", ") + entries[i];
  g_free(entries);
  return text;
}

bool is_whole_number(const nlohmann::json& value) {
  if (value.is_number_integer()) return true;
  return value.is_number_float() && std::trunc(value.get<double>()) == value.get<double>();
}

}  // namespace

CameraFeatures::CameraFeatures(ArvDevice* device, std::string camera)
    : device_(device), camera_(std::move(camera)) {}

std::string CameraFeatures::where(const std::string& name) const {
  return "feature '" + name + "' of camera " + camera_;
}

ArvGcFeatureNode* CameraFeatures::node(const std::string& name) const {
  ArvGcNode* found = arv_device_get_feature(device_, name.c_str());
  if (found == nullptr || !ARV_IS_GC_FEATURE_NODE(found)) {
    throw Error("camera " + camera_ + " has no feature '" + name + "'");
  }
  return ARV_GC_FEATURE_NODE(found);
}

bool CameraFeatures::available(const std::string& name) const {
  ArvGcNode* found = arv_device_get_feature(device_, name.c_str());
  if (found == nullptr || !ARV_IS_GC_FEATURE_NODE(found)) return false;
  ArvGcFeatureNode* feature = ARV_GC_FEATURE_NODE(found);
  return arv_gc_feature_node_is_implemented(feature, nullptr) &&
         arv_gc_feature_node_is_available(feature, nullptr);
}

std::string CameraFeatures::set(const std::string& name, const nlohmann::json& value) {
  ArvGcFeatureNode* feature = node(name);
  GErrorSlot error;
  if (!arv_gc_feature_node_is_implemented(feature, error.out())) {
    throw Error(where(name) + " is not implemented");
  }
  if (!arv_gc_feature_node_is_available(feature, error.out())) {
    throw Error(where(name) + " is not available in the current configuration");
  }
  if (arv_gc_feature_node_get_actual_access_mode(feature) == ARV_GC_ACCESS_MODE_RO) {
    throw Error(where(name) + " is read-only");
  }
  const std::string doing = "setting " + where(name) + " to " + value.dump();
  auto wrong_type = [&](const std::string& expected) {
    return Error(where(name) + " is " + expected + ", got " + value.dump());
  };
  if (ARV_IS_GC_ENUMERATION(feature)) {
    auto* enumeration = ARV_GC_ENUMERATION(feature);
    if (value.is_string()) {
      arv_gc_enumeration_set_string_value(enumeration, value.get<std::string>().c_str(),
                                          error.out());
    } else if (value.is_number_integer()) {
      arv_gc_enumeration_set_int_value(enumeration, value.get<std::int64_t>(), error.out());
    } else {
      throw wrong_type("an enumeration (" + enumeration_entries(enumeration) +
                       "); expected an entry name");
    }
    if (error.failed()) {
      throw Error(doing + ": " + error.message() +
                  " (entries available now: " + enumeration_entries(enumeration) + ")");
    }
  } else if (ARV_IS_GC_BOOLEAN(feature)) {
    if (!value.is_boolean()) throw wrong_type("a boolean; expected true or false");
    arv_gc_boolean_set_value(ARV_GC_BOOLEAN(feature), value.get<bool>(), error.out());
  } else if (ARV_IS_GC_COMMAND(feature)) {
    if (value != true) throw wrong_type("a command; expected true (execute it)");
    arv_gc_command_execute(ARV_GC_COMMAND(feature), error.out());
    error.check(doing);
    return "executed";
  } else if (ARV_IS_GC_STRING(feature)) {
    if (!value.is_string()) throw wrong_type("a string; expected a string");
    arv_gc_string_set_value(ARV_GC_STRING(feature), value.get<std::string>().c_str(), error.out());
  } else if (ARV_IS_GC_INTEGER(feature)) {
    if (!is_whole_number(value)) throw wrong_type("an integer; expected a whole number");
    arv_gc_integer_set_value(ARV_GC_INTEGER(feature), static_cast<gint64>(value.get<double>()),
                             error.out());
  } else if (ARV_IS_GC_FLOAT(feature)) {
    if (!value.is_number()) throw wrong_type("a float; expected a number");
    arv_gc_float_set_value(ARV_GC_FLOAT(feature), value.get<double>(), error.out());
  } else {
    throw Error(where(name) + " is a " + node_type(feature) + ", which cannot be set");
  }
  error.check(doing);
  return read(name);
}

std::string CameraFeatures::read(const std::string& name) const {
  ArvGcFeatureNode* feature = node(name);
  GErrorSlot error;
  const char* text = arv_gc_feature_node_get_value_as_string(feature, error.out());
  error.check("reading " + where(name));
  return text != nullptr ? text : "";
}

double CameraFeatures::read_number(const std::string& name) const {
  ArvGcFeatureNode* feature = node(name);
  GErrorSlot error;
  double number = 0.0;
  if (ARV_IS_GC_FLOAT(feature)) {
    number = arv_gc_float_get_value(ARV_GC_FLOAT(feature), error.out());
  } else if (ARV_IS_GC_INTEGER(feature)) {
    number = static_cast<double>(arv_gc_integer_get_value(ARV_GC_INTEGER(feature), error.out()));
  } else {
    throw Error(where(name) + " is a " + node_type(feature) + ", not a number");
  }
  error.check("reading " + where(name));
  return number;
}

std::vector<FeatureRow> list_features(ArvDevice* device) {
  ArvGc* genicam = arv_device_get_genicam(device);
  std::vector<FeatureRow> rows;
  std::function<void(const char*, int)> visit = [&](const char* name, int depth) {
    ArvGcNode* found = arv_gc_get_node(genicam, name);
    if (found == nullptr || !ARV_IS_GC_FEATURE_NODE(found)) return;
    ArvGcFeatureNode* feature = ARV_GC_FEATURE_NODE(found);
    if (!arv_gc_feature_node_is_implemented(feature, nullptr)) return;
    FeatureRow row;
    row.depth = depth;
    row.name = name;
    row.type = node_type(feature);
    if (ARV_IS_GC_CATEGORY(feature)) {
      row.category = true;
      rows.push_back(row);
      for (const GSList* member = arv_gc_category_get_features(ARV_GC_CATEGORY(feature));
           member != nullptr; member = member->next) {
        visit(static_cast<const char*>(member->data), depth + 1);
      }
      return;
    }
    row.access = access_text(feature);
    if (!ARV_IS_GC_COMMAND(feature) && row.access != "WO" && row.access != "NA") {
      GErrorSlot error;
      const char* value = arv_gc_feature_node_get_value_as_string(feature, error.out());
      row.value = error.failed() ? "(unreadable: " + error.message() + ")"
                                 : (value != nullptr ? value : "");
    }
    rows.push_back(row);
  };
  ArvGcNode* root = arv_gc_get_node(genicam, "Root");
  if (root != nullptr && ARV_IS_GC_CATEGORY(root)) {
    for (const GSList* member = arv_gc_category_get_features(ARV_GC_CATEGORY(root));
         member != nullptr; member = member->next) {
      visit(static_cast<const char*>(member->data), 0);
    }
  }
  return rows;
}

}  // namespace tilth::aravis
