// Prints one line per frame to standard output: the frame id and a summary of the
// message received, and of a second one when `also` is connected (a measurement beside
// its ground truth). Accepts any message type.
#include <iostream>
#include <mutex>

#include "tilth/plugin.h"

namespace tilth::sinks {
namespace {

class Console final : public Sink {
 public:
  enum Port { kIn = 0, kAlso = 1 };

  explicit Console(const StageContext& context)
      : every_(static_cast<std::uint64_t>(context.params.integer("every"))),
        label_(context.params.string("label")) {}

  void consume(const Frame& frame) override {
    if (frame.info().sequence % every_ != 0) return;
    std::cout << label_ << "frame " << frame.info().frame_id << ": "
              << frame.input(kIn).message()->summary();
    if (!frame.input(kAlso).empty()) std::cout << " | " << frame.input(kAlso).message()->summary();
    std::cout << "\n";
  }

  void skipped(const FrameInfo& info) override {
    if (info.sequence % every_ != 0) return;
    std::cout << label_ << "frame " << info.frame_id << ": no data\n";
  }

  void finish() override { std::cout.flush(); }

 private:
  const std::uint64_t every_;
  const std::string label_;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "sinks.console";
  d.summary = "prints one line per frame with a summary of the message";
  d.inputs = {PortSpec::any("in", "any message"),
              PortSpec::any("also", "printed after the first, when connected").optional()};
  d.params = {
      ParamSpec::integer("every", 1).range(1, std::nullopt).describe("print every n-th frame"),
      ParamSpec::string("label", "").describe("text put before each line"),
  };
  d.create = factory<Console>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::sinks
