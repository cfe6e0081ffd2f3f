// teststop.slow_finish: a sink whose finish() takes finish_ms, so a test can send a
// second stop signal while a tool is still stopping from the first.
#include <chrono>
#include <thread>

#include "tilth/messages/ground_distance.h"
#include "tilth/plugin.h"

namespace {

class SlowFinish final : public tilth::Sink {
 public:
  explicit SlowFinish(const tilth::StageContext& context)
      : finish_time_(std::chrono::milliseconds(context.params.integer("finish_ms"))) {}
  void consume(const tilth::Frame&) override {}
  void finish() override { std::this_thread::sleep_for(finish_time_); }

 private:
  const std::chrono::milliseconds finish_time_;
};

tilth::StageDescriptor describe() {
  tilth::StageDescriptor d;
  d.type = "teststop.slow_finish";
  d.summary = "a sink that takes finish_ms to finish";
  d.inputs = {tilth::PortSpec::of<tilth::GroundDistance>("distance", "any")};
  d.params = {tilth::ParamSpec::integer("finish_ms", 10000)
                  .range(0, std::nullopt)
                  .in_unit("ms")
                  .describe("time finish() takes")};
  d.create = tilth::factory<SlowFinish>();
  return d;
}

}  // namespace

TILTH_PLUGIN("teststop")
TILTH_STAGE(describe());
