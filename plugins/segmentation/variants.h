// The segmentation variants that share segmentation.color_threshold's ports, declared so
// that tests, benchmarks and tools can make them without loading the plugin.
#pragma once

#include "tilth/stage_descriptor.h"

namespace tilth::segmentation {

StageDescriptor describe_color_index();
StageDescriptor describe_lab_clusters();
StageDescriptor describe_pixel_classifier();
StageDescriptor describe_cnn();
StageDescriptor describe_depth_aided();
StageDescriptor describe_fusion();
StageDescriptor describe_self_trained();

}  // namespace tilth::segmentation
