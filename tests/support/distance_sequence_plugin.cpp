// A test source of known ground distances, for the output tests (Modbus, CSV): frame i
// carries distance start_mm + i * step_mm (rounded to 0.01 mm), soil fraction and
// confidence that change with i, and every invalid_every-th frame is invalid for too
// little soil. After `frames` frames it either ends the stream or idles until the graph
// stops, so a test can watch an output go stale.
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "tilth/messages/ground_distance.h"
#include "tilth/plugin.h"

namespace {

class DistanceSequence final : public tilth::Source {
 public:
  explicit DistanceSequence(const tilth::StageContext& context)
      : frames_(context.params.integer("frames")),
        first_frame_id_(static_cast<std::uint64_t>(context.params.integer("first_frame_id"))),
        start_mm_(context.params.number("start_mm")),
        step_mm_(context.params.number("step_mm")),
        invalid_every_(context.params.integer("invalid_every")),
        idle_at_end_(context.params.string("then") == "idle"),
        period_(context.params.number("fps") > 0
                    ? std::chrono::nanoseconds(
                          static_cast<std::int64_t>(1e9 / context.params.number("fps")))
                    : std::chrono::nanoseconds(0)),
        next_(std::chrono::steady_clock::now()) {}

  bool produce(tilth::Frame& frame) override {
    if (frames_ > 0 && index_ >= frames_) {
      if (!idle_at_end_) return false;
      std::unique_lock lock(mutex_);
      interrupted_.wait(lock, [this] { return stopping_; });
      return false;
    }
    if (period_.count() > 0) {
      std::this_thread::sleep_until(next_);
      next_ += period_;
    }
    tilth::GroundDistance distance;
    distance.distance_mm =
        std::round((start_mm_ + step_mm_ * static_cast<double>(index_)) * 100.0) / 100.0;
    distance.valid = invalid_every_ == 0 || (index_ + 1) % invalid_every_ != 0;
    if (!distance.valid)
      distance.invalidate(tilth::InvalidCause::kTooLittleSoil, "too little visible soil");
    distance.soil_fraction = static_cast<double>(index_ % 97) / 100.0 + 0.0012;
    distance.soil_pixels = 1000 + index_;
    distance.spread_mm = 1.5;
    distance.confidence = static_cast<double>(index_ % 89) / 100.0 + 0.005;
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    const auto now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now).count();
    frame.set_capture(first_frame_id_ + static_cast<std::uint64_t>(index_), now_ns, now_ns);
    frame.emit(0, std::move(distance));
    ++index_;
    return true;
  }

  void interrupt() override {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    interrupted_.notify_all();
  }

 private:
  const std::int64_t frames_;
  const std::uint64_t first_frame_id_;
  const double start_mm_;
  const double step_mm_;
  const std::int64_t invalid_every_;
  const bool idle_at_end_;
  const std::chrono::nanoseconds period_;
  std::chrono::steady_clock::time_point next_;
  std::int64_t index_ = 0;
  std::mutex mutex_;
  std::condition_variable interrupted_;
  bool stopping_ = false;
};

tilth::StageDescriptor describe() {
  using tilth::ParamSpec;
  tilth::StageDescriptor d;
  d.type = "testdistance.sequence";
  d.summary = "known ground distances for output tests";
  d.outputs = {tilth::PortSpec::of<tilth::GroundDistance>("distance", "the sequence")};
  d.params = {
      ParamSpec::integer("frames", 10).range(0, std::nullopt).describe("0 = endless"),
      ParamSpec::choice("then", {"end", "idle"}, "end").describe("after the last frame"),
      ParamSpec::integer("first_frame_id", 0).range(0, std::nullopt).describe("id of frame 0"),
      ParamSpec::number("start_mm", 518.23).describe("distance of frame 0"),
      ParamSpec::number("step_mm", 0.37).describe("added per frame"),
      ParamSpec::integer("invalid_every", 0).range(0, std::nullopt).describe("0 = never"),
      ParamSpec::number("fps", 50).range(0, 10000).describe("0 = as fast as possible"),
  };
  d.create = tilth::factory<DistanceSequence>();
  return d;
}

}  // namespace

TILTH_PLUGIN("testdistance")
TILTH_STAGE(describe());
