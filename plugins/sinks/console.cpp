// Prints one line per frame to standard output: the frame id and a summary of the
// message received, and of a second one when `also` is connected (a measurement beside
// its ground truth). Accepts any message type. Each line is flushed as it is printed, so
// that a reader sees it at once; when the reader goes (`tilth run ... | head -1`), the
// run ends.
#include <cerrno>
#include <cstring>
#include <iostream>

#include "tilth/plugin.h"

namespace tilth::sinks {
namespace {

class Console final : public Sink {
 public:
  enum Port { kIn = 0, kAlso = 1 };

  explicit Console(const StageContext& context)
      : every_(static_cast<std::uint64_t>(context.params.integer("every"))),
        label_(context.params.string("label")),
        end_run_(context.end_run) {}

  void consume(const Frame& frame) override {
    if (frame.info().sequence % every_ != 0 || closed_) return;
    std::cout << label_ << "frame " << frame.info().frame_id << ": "
              << frame.input(kIn).message()->summary();
    if (!frame.input(kAlso).empty()) std::cout << " | " << frame.input(kAlso).message()->summary();
    end_line();
  }

  void skipped(const FrameInfo& info) override {
    if (info.sequence % every_ != 0 || closed_) return;
    std::cout << label_ << "frame " << info.frame_id << ": no data";
    end_line();
  }

 private:
  void end_line() {
    std::cout << std::endl;
    if (std::cout) return;
    const int error = errno;
    closed_ = true;
    end_run_(std::string("standard output is closed (") +
             (error != 0 ? std::strerror(error) : "write failed") +
             "): nothing more can be printed");
  }

  const std::uint64_t every_;
  const std::string label_;
  const std::function<void(const std::string&)> end_run_;
  bool closed_ = false;
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
