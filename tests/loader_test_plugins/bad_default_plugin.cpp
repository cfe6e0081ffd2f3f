// A plugin whose parameter default contradicts its own range.
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
  d.type = "baddefault.pass";
  d.summary = "bad default";
  d.inputs = {tilth::PortSpec::of<tilth::RawTofFrame>("in", "raw")};
  d.outputs = {tilth::PortSpec::of<tilth::RawTofFrame>("out", "raw")};
  d.params = {tilth::ParamSpec::integer("kernel", 40).range(1, 31).describe("kernel size")};
  d.create = tilth::factory<Pass>();
  return d;
}

}  // namespace

TILTH_PLUGIN("baddefault")
TILTH_STAGE(describe());
