// A well-formed plugin with a transform and a stage whose constructor throws.
#include <stdexcept>

#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace {

class Pass final : public tilth::Transform {
 public:
  explicit Pass(const tilth::StageContext&) {}
  void process(tilth::Frame& frame) override { frame.set_output(0, frame.input(0).message()); }
};

class Throws final : public tilth::Transform {
 public:
  explicit Throws(const tilth::StageContext& context) {
    throw std::runtime_error("device " + context.params.string("device") + " is not connected");
  }
  void process(tilth::Frame&) override {}
};

tilth::StageDescriptor describe(std::string type, tilth::StageFactory create) {
  tilth::StageDescriptor d;
  d.type = std::move(type);
  d.summary = "test";
  d.inputs = {tilth::PortSpec::of<tilth::RawTofFrame>("in", "raw")};
  d.outputs = {tilth::PortSpec::of<tilth::RawTofFrame>("out", "raw")};
  d.params = {tilth::ParamSpec::string("device", "cam0").describe("device name")};
  d.create = std::move(create);
  return d;
}

}  // namespace

TILTH_PLUGIN("testgood")
TILTH_STAGE(describe("testgood.pass", tilth::factory<Pass>()));
TILTH_STAGE(describe("testgood.throws", tilth::factory<Throws>()));
