// estimation.temporal: the ground distance over time, after an estimator. It holds the
// last accepted distance over frames without one (for at most max_hold_ms, marked held),
// rejects a single frame that jumps away from it, follows a real step as soon as
// confirm_frames consecutive frames agree on it, and optionally smooths with a stated
// time constant.
//
//   valid, within outlier_mm of the track ──► accepted (smoothed) ─────────────► distance
//   valid, farther ──► agrees with the frames before it? ── confirm_frames ──► accepted at once
//                                                  └── not yet ──► held ───────► distance
//   invalid ──► held while the track is younger than max_hold_ms, else passed on as it is
//
// Times are the frames' host capture times. A held distance is valid, with held set and
// held_ms its age at this frame; past max_hold_ms, or at a capture time before the
// track's last, the track ends and the next valid distance starts a new one, whatever it is.
//
//   "filter": {"type": "estimation.temporal",
//              "params": {"max_hold_ms": 200, "outlier_mm": 3, "confirm_frames": 2}}
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "estimators.h"
#include "tilth/message_pool.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/plugin.h"

namespace tilth::estimation {
namespace {

struct Track {
  double distance_mm;
  std::int64_t accepted_ns;  // capture time of the last frame accepted into it
  GroundDistance measured;   // that frame's measurement
};

class Temporal final : public Transform {
 public:
  explicit Temporal(const StageContext& context)
      : max_hold_ns_(static_cast<std::int64_t>(context.params.number("max_hold_ms") * 1e6)),
        outlier_mm_(context.params.number("outlier_mm")),
        confirm_frames_(static_cast<std::size_t>(context.params.integer("confirm_frames"))),
        smoothing_ns_(context.params.number("smoothing_ms") * 1e6) {}

  void process(Frame& frame) override {
    const GroundDistance& in = frame.input<GroundDistance>(0);
    const std::int64_t now_ns = frame.info().host_timestamp_ns;
    // Past max_hold_ms, or before the track's last frame (a replay that loops, a clock set
    // back), the track ends.
    if (track_ && (now_ns < track_->accepted_ns || now_ns - track_->accepted_ns > max_hold_ns_)) {
      track_.reset();
    }

    if (!in.valid) {
      candidates_.clear();
      frame.set_output(0, track_ ? held(now_ns) : copy(in));
    } else if (!track_ || std::abs(in.distance_mm - track_->distance_mm) <= outlier_mm_) {
      candidates_.clear();
      track_ = Track{track_ ? smoothed(in.distance_mm, now_ns) : in.distance_mm, now_ns, in};
      frame.set_output(0, shown());
    } else if (confirms_step(in.distance_mm)) {
      candidates_.clear();
      track_ = Track{in.distance_mm, now_ns, in};
      frame.set_output(0, shown());
    } else {
      frame.set_output(0, held(now_ns));
    }
  }

 private:
  // Whether `distance_mm`, with the outliers just before it, makes confirm_frames
  // consecutive frames within outlier_mm of each other; it starts the run again if not.
  bool confirms_step(double distance_mm) {
    candidates_.push_back(distance_mm);
    const auto [low, high] = std::minmax_element(candidates_.begin(), candidates_.end());
    if (*high - *low > outlier_mm_) candidates_.assign({distance_mm});
    return candidates_.size() >= confirm_frames_;
  }

  // First-order low-pass over the capture times: a step of the input reaches 63 % of its
  // height after smoothing_ms, and a ramp lags by smoothing_ms.
  double smoothed(double distance_mm, std::int64_t now_ns) const {
    if (smoothing_ns_ <= 0.0) return distance_mm;
    const double elapsed_ns =
        static_cast<double>(std::max<std::int64_t>(now_ns - track_->accepted_ns, 0));
    const double weight = 1.0 - std::exp(-elapsed_ns / smoothing_ns_);
    return track_->distance_mm + weight * (distance_mm - track_->distance_mm);
  }

  std::shared_ptr<GroundDistance> copy(const GroundDistance& in) {
    auto out = pool_.acquire();
    *out = in;
    return out;
  }

  // The track's distance, with the rest of the measurement it was last accepted from.
  std::shared_ptr<GroundDistance> shown() {
    auto out = copy(track_->measured);
    out->distance_mm = track_->distance_mm;
    return out;
  }

  std::shared_ptr<GroundDistance> held(std::int64_t now_ns) {
    auto out = shown();
    out->held = true;
    out->held_ms = static_cast<double>(now_ns - track_->accepted_ns) / 1e6;
    return out;
  }

  const std::int64_t max_hold_ns_;
  const double outlier_mm_;
  const std::size_t confirm_frames_;
  const double smoothing_ns_;
  std::optional<Track> track_;
  std::vector<double> candidates_;  // consecutive valid distances away from the track
  MessagePool<GroundDistance> pool_;
};

}  // namespace

StageDescriptor describe_temporal() {
  StageDescriptor d;
  d.type = "estimation.temporal";
  d.summary = "the ground distance over time: held over gaps, single-frame outliers rejected";
  d.inputs = {PortSpec::of<GroundDistance>("distance", "an estimator's distance, every frame")};
  d.outputs = {PortSpec::of<GroundDistance>(
      "distance", "the distance to serve; held (with its age) while the input has none")};
  d.params = {
      ParamSpec::number("max_hold_ms", 200.0)
          .range(0, 10000)
          .in_unit("ms")
          .describe("how long the last accepted distance is held over frames without one "
                    "(or with an outlier), on the frames' capture times; 0 = never held"),
      ParamSpec::number("outlier_mm", 3.0)
          .range(0.1, 1000)
          .in_unit("mm")
          .describe("a valid distance farther than this from the held one is an outlier until "
                    "confirm_frames frames agree on it"),
      ParamSpec::integer("confirm_frames", 2)
          .range(1, 30)
          .describe("consecutive frames within outlier_mm of each other that make a jump a "
                    "real step, followed at once; 1 = no outlier rejection"),
      ParamSpec::number("smoothing_ms", 0.0)
          .range(0, 10000)
          .in_unit("ms")
          .describe("time constant of a first-order low-pass over accepted distances (a ramp "
                    "lags by about this much; confirmed steps are not smoothed); 0 = none"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<Temporal>();
  return d;
}

TILTH_STAGE(describe_temporal());

}  // namespace tilth::estimation
