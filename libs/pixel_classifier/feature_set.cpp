#include "pixel_classifier/feature_set.h"

#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

std::vector<std::string> texture_names() {
  std::vector<std::string> names = {"Y/median", "r", "g", "log R/G", "log B/G", "S", "gradient"};
  for (const int side : kTextureWindowsPx) {
    const std::string at = "@" + std::to_string(side);
    for (const char* name : {"mean", "std", "contrast", "gradient rms", "coherence"}) {
      names.push_back(name + at);
    }
  }
  return names;
}

}  // namespace

std::string_view feature_set_id(FeatureSet set) {
  return set == FeatureSet::kColour ? "colour/1" : "texture/1";
}

FeatureSet feature_set_of(std::string_view id) {
  if (id == "colour/1") return FeatureSet::kColour;
  if (id == "texture/1") return FeatureSet::kTexture;
  throw Error("feature set \"" + std::string(id) + "\" (expected \"colour/1\" or \"texture/1\")");
}

FeatureSet feature_set_named(std::string_view name) {
  if (name == "colour") return FeatureSet::kColour;
  if (name == "texture") return FeatureSet::kTexture;
  throw Error("feature set \"" + std::string(name) + "\" (expected colour or texture)");
}

const std::vector<std::string>& feature_names(FeatureSet set) {
  static const std::vector<std::string> colour = {"L*", "a*",  "b*",    "H",    "S",
                                                  "V",  "exg", "a*/L*", "b*/L*"};
  static const std::vector<std::string> texture = texture_names();
  return set == FeatureSet::kColour ? colour : texture;
}

}  // namespace tilth::segmentation
