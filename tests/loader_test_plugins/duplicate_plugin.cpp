// A plugin that claims a stage type the good test plugin already provides.
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace {

class Pass final : public tilth::Transform {
 public:
  explicit Pass(const tilth::StageContext&) {}
  void process(tilth::Frame&) override {}
};

tilth::StageDescriptor describe() {
  tilth::StageDescriptor d;
  d.type = "testgood.pass";
  d.summary = "duplicate";
  d.inputs = {tilth::PortSpec::of<tilth::RawTofFrame>("in", "raw")};
  d.outputs = {tilth::PortSpec::of<tilth::RawTofFrame>("out", "raw")};
  d.create = tilth::factory<Pass>();
  return d;
}

}  // namespace

TILTH_PLUGIN("duplicate")
TILTH_STAGE(describe());
