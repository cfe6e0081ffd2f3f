// The feature sets a pixel classifier can be trained on, by the name and version a model
// file records (docs/segmentation-variants.md lists what each feature is).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace tilth::segmentation {

enum class FeatureSet {
  kColour,   // "colour/1": the 3x3 mean colour of the pixel (the features of format 1)
  kTexture,  // "texture/1": shading-invariant colour, normalised luminance, texture at 3 scales
};

// "colour/1", "texture/1".
std::string_view feature_set_id(FeatureSet set);
// The set of an id; throws tilth::Error listing the known ids.
FeatureSet feature_set_of(std::string_view id);
// The short names "colour", "texture" (as --features takes them).
FeatureSet feature_set_named(std::string_view name);

// The names of the feature columns, in order.
const std::vector<std::string>& feature_names(FeatureSet set);

// The side of the box windows of the texture features, px.
inline constexpr int kTextureWindowsPx[] = {5, 11, 23};

}  // namespace tilth::segmentation
