// A plugin built by another compiler on the runtime's libraries: loaded, with a warning.
#include "tilth/plugin.h"

namespace {

std::vector<tilth::StageDescriptor> no_stages;

}  // namespace

extern "C" __attribute__((visibility("default"))) const tilth::PluginDescriptor*
tilth_plugin_descriptor() {
  static const tilth::PluginDescriptor descriptor{
      tilth::kAbiVersion, sizeof(tilth::PluginDescriptor), "other_compiler", &no_stages,
      tilth::BuildStamp{"Some Compiler 99", tilth::kThisBuild.standard_library,
                        tilth::kThisBuild.opencv, tilth::kThisBuild.json}};
  return &descriptor;
}
