// A plugin built on another OpenCV than the runtime: refused, the difference named.
#include "tilth/plugin.h"

namespace {

std::vector<tilth::StageDescriptor> no_stages;

}  // namespace

extern "C" __attribute__((visibility("default"))) const tilth::PluginDescriptor*
tilth_plugin_descriptor() {
  static const tilth::PluginDescriptor descriptor{
      tilth::kAbiVersion, sizeof(tilth::PluginDescriptor), "other_opencv", &no_stages,
      tilth::BuildStamp{tilth::kThisBuild.compiler, tilth::kThisBuild.standard_library, "3.4",
                        tilth::kThisBuild.json}};
  return &descriptor;
}
