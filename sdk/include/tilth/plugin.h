// Making a shared library a Tilth plugin. Once per library:
//   TILTH_PLUGIN("synthetic")
// and once per stage file, after the stage's class:
//   TILTH_STAGE(describe_tof_plane())
#pragma once

#include <cstdint>
#include <vector>

#include "tilth/abi.h"
#include "tilth/build_stamp.h"
#include "tilth/stage_descriptor.h"

namespace tilth {

// The one symbol a plugin exports (`tilth_plugin_descriptor`) returns this. The runtime
// checks abi_version and size before reading any other field, then the build stamp.
struct PluginDescriptor {
  std::uint32_t abi_version;
  std::uint32_t size;
  const char* name;
  const std::vector<StageDescriptor>* stages;
  BuildStamp build;
};

namespace detail {

// One list per plugin library (hidden visibility keeps each library's own).
__attribute__((visibility("hidden"))) std::vector<StageDescriptor>& plugin_stages();

struct StageRegistration {
  explicit StageRegistration(StageDescriptor descriptor) {
    plugin_stages().push_back(std::move(descriptor));
  }
};

}  // namespace detail
}  // namespace tilth

#define TILTH_PLUGIN(plugin_name)                                                    \
  __attribute__((visibility("hidden"))) std::vector<::tilth::StageDescriptor>&       \
  tilth::detail::plugin_stages() {                                                   \
    static std::vector<::tilth::StageDescriptor> stages;                             \
    return stages;                                                                   \
  }                                                                                  \
  extern "C" __attribute__((visibility("default"))) const ::tilth::PluginDescriptor* \
  tilth_plugin_descriptor() {                                                        \
    static const ::tilth::PluginDescriptor descriptor{                               \
        ::tilth::kAbiVersion, sizeof(::tilth::PluginDescriptor), plugin_name,        \
        &::tilth::detail::plugin_stages(), ::tilth::kThisBuild};                     \
    return &descriptor;                                                              \
  }

#define TILTH_STAGE_CONCAT_(a, b) a##b
#define TILTH_STAGE_CONCAT(a, b) TILTH_STAGE_CONCAT_(a, b)
#define TILTH_STAGE(descriptor_expression)                            \
  static const ::tilth::detail::StageRegistration TILTH_STAGE_CONCAT( \
      tilth_stage_, __LINE__)(descriptor_expression)
