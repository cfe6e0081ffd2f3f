// example.centre_range: the range (gray * mm per gray) at one pixel of a raw ToF frame.
#include "centre_range.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace example {

class CentreRangeStage final : public tilth::Transform {
 public:
  explicit CentreRangeStage(const tilth::StageContext& context)
      : gray_to_mm_(context.params.number("gray_to_mm")),
        u_(static_cast<int>(context.params.integer("u"))),
        v_(static_cast<int>(context.params.integer("v"))) {}

  void process(tilth::Frame& frame) override {
    const auto& raw = frame.input<tilth::RawTofFrame>(0);
    CentreRange range;
    range.range_mm = raw.gray.at<std::uint16_t>(v_, u_) * gray_to_mm_;
    frame.emit(0, range);
  }

 private:
  const double gray_to_mm_;
  const int u_;
  const int v_;
};

tilth::StageDescriptor describe_centre_range() {
  tilth::StageDescriptor d;
  d.type = "example.centre_range";
  d.summary = "range at one pixel of a raw ToF frame";
  d.inputs = {tilth::PortSpec::of<tilth::RawTofFrame>("raw", "raw ToF gray")};
  d.outputs = {tilth::PortSpec::of<CentreRange>("range", "range at the pixel")};
  d.params = {
      tilth::ParamSpec::number("gray_to_mm", 0.0229)
          .range(1e-6, std::nullopt)
          .in_unit("mm")
          .describe("millimetres per gray value"),
      tilth::ParamSpec::integer("u", 313).range(0, std::nullopt).in_unit("px").describe("column"),
      tilth::ParamSpec::integer("v", 240).range(0, std::nullopt).in_unit("px").describe("row"),
  };
  d.concurrency = tilth::Concurrency::kParallel;
  d.create = tilth::factory<CentreRangeStage>();
  return d;
}

}  // namespace example

TILTH_STAGE(example::describe_centre_range());
