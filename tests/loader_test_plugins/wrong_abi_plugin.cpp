// A plugin built for another plugin ABI version.
#include "tilth/plugin.h"

extern "C" __attribute__((visibility("default"))) const tilth::PluginDescriptor*
tilth_plugin_descriptor() {
  static const tilth::PluginDescriptor descriptor{tilth::kAbiVersion + 1,
                                                  sizeof(tilth::PluginDescriptor), "future",
                                                  nullptr, tilth::kThisBuild};
  return &descriptor;
}
