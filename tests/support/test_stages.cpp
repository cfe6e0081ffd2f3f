#include "test_stages.h"

#include <chrono>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <thread>

#include "tilth/stage_descriptor.h"

namespace tilth::testing {
namespace {

std::mutex logs_mutex;
std::map<std::string, std::unique_ptr<SinkLog>> logs;
std::atomic<int> delays_now{0};
std::atomic<int> delays_max{0};

void note_max(std::atomic<int>& max, int value) {
  int seen = max.load();
  while (value > seen && !max.compare_exchange_weak(seen, value)) {
  }
}

// Emits 0, step, 2 step, ... `count` frames (0: endless); optionally paced, and late to
// start (as a camera's first frame).
class Counter final : public Source {
 public:
  explicit Counter(const StageContext& c)
      : count_(c.params.integer("count")),
        period_us_(c.params.integer("period_us")),
        start_delay_us_(c.params.integer("start_delay_us")),
        step_(c.params.integer("step")) {}
  bool produce(Frame& frame) override {
    if (count_ > 0 && produced_ >= count_) return false;
    if (produced_ == 0 && start_delay_us_ > 0) {
      std::this_thread::sleep_for(std::chrono::microseconds(start_delay_us_));
    }
    if (period_us_ > 0) std::this_thread::sleep_for(std::chrono::microseconds(period_us_));
    const std::int64_t value = produced_++ * step_;
    frame.set_capture(static_cast<std::uint64_t>(value), value * 1000, 0);
    frame.emit(0, Count(value));
    return true;
  }
  void interrupt() override { interrupted_ = true; }

 private:
  const std::int64_t count_;
  const std::int64_t period_us_;
  const std::int64_t start_delay_us_;
  const std::int64_t step_;
  std::int64_t produced_ = 0;
  std::atomic<bool> interrupted_{false};
};

// Adds `add`, after sleeping a pseudo-random time below `max_delay_us` (so frames
// overtake each other in a parallel stage).
class Delay final : public Transform {
 public:
  explicit Delay(const StageContext& c)
      : add_(c.params.integer("add")), max_delay_us_(c.params.integer("max_delay_us")) {}
  void process(Frame& frame) override {
    note_max(delays_max, ++delays_now);
    const auto value = frame.input<Count>(0).value;
    if (max_delay_us_ > 0) {
      std::minstd_rand random(static_cast<std::uint32_t>(value * 7919 + 1));
      std::this_thread::sleep_for(std::chrono::microseconds(random() % max_delay_us_));
    }
    --delays_now;
    frame.emit(0, Count(value + add_));
  }

 private:
  const std::int64_t add_;
  const std::int64_t max_delay_us_;
};

class Add final : public Transform {
 public:
  explicit Add(const StageContext&) {}
  void process(Frame& frame) override {
    frame.emit(0, Count(frame.input<Count>(0).value + frame.input<Count>(1).value));
  }
};

// Throws on the frames whose value is a multiple of `every` (0: never), or in its
// constructor when `fail_to_start` is set.
class Fail final : public Transform {
 public:
  explicit Fail(const StageContext& c) : every_(c.params.integer("every")) {
    if (c.params.boolean("fail_to_start")) throw Error("camera 'xyz' not found");
  }
  void process(Frame& frame) override {
    const auto value = frame.input<Count>(0).value;
    if (every_ > 0 && value % every_ == 0) throw Error("bad value " + std::to_string(value));
    frame.emit(0, Count(value));
  }

 private:
  const std::int64_t every_;
};

// Pairs equal counts from its two inputs, whatever order they arrive in, and emits their
// sum; a count whose partner never comes is dropped once the other side has passed it.
class PairEqual final : public Synchronizer {
 public:
  explicit PairEqual(const StageContext&) {}
  void accept(const Frame& arrived, Output& output) override {
    const std::size_t side = arrived.input(0).empty() ? 1 : 0;
    const std::int64_t value = arrived.input<Count>(side).value;
    auto& other = pending_[1 - side];
    while (!other.empty() && other.front() < value) other.pop_front();
    if (other.empty() || other.front() != value) {
      pending_[side].push_back(value);
      return;
    }
    other.pop_front();
    Frame& frame = output.emit();
    frame.set_capture(static_cast<std::uint64_t>(value), value * 1000, 0);
    frame.emit(0, Count(2 * value));
  }

 private:
  std::deque<std::int64_t> pending_[2];
};

class Record final : public Sink {
 public:
  explicit Record(const StageContext& c)
      : log_(sink_log(c.node)), delay_us_(c.params.integer("delay_us")) {}
  void consume(const Frame& frame) override {
    note_max(log_.max_concurrent, ++log_.concurrent);
    if (delay_us_ > 0) std::this_thread::sleep_for(std::chrono::microseconds(delay_us_));
    {
      std::lock_guard lock(log_.mutex);
      log_.frames.push_back({frame.info(), frame.input<Count>(0).value, false});
    }
    --log_.concurrent;
  }
  void skipped(const FrameInfo& info) override {
    std::lock_guard lock(log_.mutex);
    log_.frames.push_back({info, 0, true});
  }
  void finish() override {
    std::lock_guard lock(log_.mutex);
    log_.finished = true;
  }

 private:
  SinkLog& log_;
  const std::int64_t delay_us_;
};

// Asks for the pipeline's metrics in its constructor, as a stage with a thread of its own
// (a server) may at any moment once it exists; then records as test.record does.
class MetricsProbe final : public Sink {
 public:
  explicit MetricsProbe(const StageContext& c) : log_(sink_log(c.node)) {
    log_.stages_in_metrics_at_start = c.pipeline_metrics().stages.size();
  }
  void consume(const Frame& frame) override {
    std::lock_guard lock(log_.mutex);
    log_.frames.push_back({frame.info(), frame.input<Count>(0).value, false});
  }

 private:
  SinkLog& log_;
};

// Reports every `every`-th frame (by value) as lost data, as a writer on a full disk does.
class Lossy final : public Sink {
 public:
  explicit Lossy(const StageContext& c)
      : every_(c.params.integer("every")), report_data_loss_(c.report_data_loss) {}
  void consume(const Frame& frame) override {
    const std::int64_t value = frame.input<Count>(0).value;
    if (value % every_ == 0) {
      report_data_loss_(1, "value " + std::to_string(value) + " not stored");
    }
  }

 private:
  const std::int64_t every_;
  const std::function<void(std::uint64_t, const std::string&)> report_data_loss_;
};

StageDescriptor describe(std::string type, std::vector<PortSpec> inputs,
                         std::vector<PortSpec> outputs, std::vector<ParamSpec> params,
                         Concurrency concurrency, StageFactory create) {
  StageDescriptor d;
  d.type = std::move(type);
  d.summary = "test stage";
  d.inputs = std::move(inputs);
  d.outputs = std::move(outputs);
  d.params = std::move(params);
  d.concurrency = concurrency;
  d.create = std::move(create);
  return d;
}

}  // namespace

SinkLog& sink_log(const std::string& node) {
  std::lock_guard lock(logs_mutex);
  auto& log = logs[node];
  if (!log) log = std::make_unique<SinkLog>();
  return *log;
}

void reset_sink_logs() {
  std::lock_guard lock(logs_mutex);
  logs.clear();
  delays_max = 0;
}

int max_parallel_delays() { return delays_max.load(); }

void register_test_stages(StageRegistry& registry) {
  const auto count = [](const char* name) { return PortSpec::of<Count>(name, "a count"); };
  registry.add(
      describe("test.counter", {}, {count("out")},
               {ParamSpec::integer("count", 10).range(0, std::nullopt).describe("frames"),
                ParamSpec::integer("period_us", 0).range(0, std::nullopt).describe("pace"),
                ParamSpec::integer("start_delay_us", 0)
                    .range(0, std::nullopt)
                    .describe("before the first frame"),
                ParamSpec::integer("step", 1).range(1, std::nullopt).describe("increment")},
               Concurrency::kSerial, factory<Counter>()),
      "test_stages");
  registry.add(describe("test.delay", {count("in")}, {count("out")},
                        {ParamSpec::integer("add", 0).describe("added to the value"),
                         ParamSpec::integer("max_delay_us", 0)
                             .range(0, 1'000'000)
                             .in_unit("us")
                             .describe("longest sleep")},
                        Concurrency::kParallel, factory<Delay>()),
               "test_stages");
  registry.add(describe("test.add", {count("a"), count("b")}, {count("sum")}, {},
                        Concurrency::kParallel, factory<Add>()),
               "test_stages");
  auto pair = describe("test.pair_equal", {count("a"), count("b")}, {count("sum")}, {},
                       Concurrency::kSerial, factory<PairEqual>());
  pair.input_timing = InputTiming::kOnArrival;
  registry.add(std::move(pair), "test_stages");
  registry.add(describe("test.fail", {count("in")}, {count("out")},
                        {ParamSpec::integer("every", 0).range(0, std::nullopt).describe("period"),
                         ParamSpec::boolean("fail_to_start", false).describe("throw when made")},
                        Concurrency::kParallel, factory<Fail>()),
               "test_stages");
  registry.add(describe("test.record", {count("in")}, {},
                        {ParamSpec::integer("delay_us", 0).range(0, std::nullopt).describe("pace"),
                         ParamSpec::number("gain", 1.0).range(0, 10).in_unit("dB").describe("x"),
                         ParamSpec::choice("mode", {"fast", "exact"}, "fast").describe("mode"),
                         ParamSpec::path("file", "record.txt").describe("a file to read"),
                         ParamSpec::output_path("log", "record.log").describe("a file to write")},
                        Concurrency::kSerial, factory<Record>()),
               "test_stages");
  registry.add(describe("test.lossy", {count("in")}, {},
                        {ParamSpec::integer("every", 5).range(1, std::nullopt).describe("period")},
                        Concurrency::kSerial, factory<Lossy>()),
               "test_stages");
  registry.add(describe("test.metrics_probe", {count("in")}, {}, {}, Concurrency::kSerial,
                        factory<MetricsProbe>()),
               "test_stages");
  registry.add(describe("test.needs_path", {count("in")}, {},
                        {ParamSpec::path("file", std::nullopt).describe("a file to read")},
                        Concurrency::kSerial, factory<Record>()),
               "test_stages");
}

}  // namespace tilth::testing
