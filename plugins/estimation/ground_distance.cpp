// estimation.ground_distance: the paper's last step (section 2.4) -- one ground distance
// from the soil depths left in a region of interest, as a robust statistic.
//
//   color? ──► usable in roi? ─┐
//   soil_depth ──► finite depths in roi ──► enough soil? ──► median | trimmed mean ──► gates ──►
//   distance
//                                  └── no ──────┴── no ──► invalid, with its cause and reason
//
// Invariant: an invalid measurement carries distance_mm 0 and confidence 0; too little
// visible soil, unusable colour or an implausible number (plausibility.h) is never served
// as valid.
//
//   "estimate": {"type": "estimation.ground_distance",
//                "params": {"roi": {"x": 160, "y": 120, "width": 320, "height": 240},
//                           "statistic": "median", "min_soil_fraction": 0.05}}
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <span>
#include <vector>

#include "depth_noise/depth_noise.h"
#include "estimators.h"
#include "plausibility.h"
#include "rank_selection.h"
#include "soil_beyond.h"
#include "soil_region.h"
#include "tilth/error.h"
#include "tilth/message_pool.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/registered_color.h"
#include "tilth/plugin.h"

namespace tilth::estimation {
namespace {

constexpr float kLargest = std::numeric_limits<float>::max();

// Every second pixel of every second row tells the soil beyond the ground well enough.
constexpr int kBeyondSampleStep = 2;
// Below a third of the gate's default 10 mm the noise does not move its threshold: the
// depth noise's quick count suffices.
constexpr float kBeyondNoiseFloorMm = 3.0f;

// Scales the median absolute deviation to the standard deviation of normal data.
constexpr double kMadToSigma = 1.4826;

// How far a depth lies from the median, as the spread's ranks see it.
float deviation(float depth_mm, double median_mm) {
  return static_cast<float>(std::abs(depth_mm - median_mm));
}

// Each depth replaced by deviation(depth, median_mm).
void replace_by_deviations(std::span<float> depths, double median_mm) {
  for (float& depth : depths) depth = deviation(depth, median_mm);
}

// Where the finite depths collected so far end, and their range.
struct FiniteDepths {
  float* end;
  float lowest;
  float highest;
};

// A row's finite depths stored from found.end on, each depth stored and the end moved on
// past the finite ones, without a branch per depth. By value, restrict and not inlined,
// so that the range stays in registers while the depths are stored (inlined, GCC kept it
// in memory: 0.30 instead of 0.22 ms a frame, bench/RESULTS.md).
[[gnu::noinline]] FiniteDepths collect_finite_row(const float* __restrict depth, int width,
                                                  FiniteDepths found) {
  float* __restrict out = found.end;
  float lowest = found.lowest;
  float highest = found.highest;
  for (int col = 0; col < width; ++col) {
    const float value = depth[col];
    const bool finite = std::abs(value) <= kLargest;  // NaN, inf: false
    *out = value;
    out += finite ? 1 : 0;
    lowest = finite && value < lowest ? value : lowest;
    highest = finite && value > highest ? value : highest;
  }
  return {out, lowest, highest};
}

// The mean of what is left after dropping `trim_fraction` of the indexed values at each end.
double trimmed_mean(RankSelection& ranks, std::size_t count, double trim_fraction) {
  const auto cut = static_cast<std::size_t>(trim_fraction * static_cast<double>(count));
  return (ranks.sum_of_smallest(count - cut) - ranks.sum_of_smallest(cut)) /
         static_cast<double>(count - 2 * cut);
}

enum class Statistic { kMedian, kTrimmedMean };

class GroundDistanceEstimator final : public Transform {
 public:
  enum Port { kSoilDepth = 0, kColor = 1 };

  explicit GroundDistanceEstimator(const StageContext& context)
      : region_(context.params.json("roi"), RegionOfInterest::Whole::kMiddleHalf),
        statistic_(context.params.string("statistic") == "median" ? Statistic::kMedian
                                                                  : Statistic::kTrimmedMean),
        trim_fraction_(context.params.number("trim_fraction")),
        requirement_(soil_requirement(context.params)),
        gates_(context.params),
        log_(context.log) {}

  void process(Frame& frame) override {
    const auto& soil = frame.input<DepthImage>(kSoilDepth);
    if (soil.mm.type() != CV_32FC1) {
      throw Error("input 'soil_depth': expected a CV_32FC1 image in mm, got type " +
                  std::to_string(soil.mm.type()));
    }
    const cv::Rect roi = region_.on(soil.mm.size());
    if (region_.clipped_on(soil.mm.size())) {
      std::call_once(clipping_logged_,
                     [&] { log_.warning(region_.clipping_note(soil.mm.size())); });
    }

    thread_local std::vector<float> buffer;
    const SoilDepths depths = collect_finite(soil.mm, roi, buffer);
    const auto message = outputs_.acquire();
    GroundDistance& out = *message;
    out = GroundDistance{};  // a reused message keeps its string's buffer
    out.soil_pixels = static_cast<std::int64_t>(depths.mm.size());
    out.soil_fraction = static_cast<double>(depths.mm.size()) / roi.area();
    if (const Packet& color = frame.input(kColor); !color.empty()) {
      if (auto unusable = gates_.unusable_color(color.get<RegisteredColor>(), roi)) {
        out.invalidate(InvalidCause::kImageUnusable, std::move(*unusable));
        frame.set_output(0, message);
        return;
      }
    }
    if (auto shortfall = requirement_.shortfall(out.soil_pixels, roi.area()); !shortfall.empty()) {
      out.invalidate(InvalidCause::kTooLittleSoil, std::move(shortfall));
    } else {
      measure(depths, out);
      if (out.valid && gates_.checks_soil_beyond()) {
        gates_.check_soil_beyond(out, soil_beyond(soil.mm, roi, out.distance_mm));
      }
      gates_.check(out);
    }
    frame.set_output(0, message);
  }

 private:
  // The finite depths of a region and their range (lowest > highest when there are none).
  struct SoilDepths {
    std::span<float> mm;
    float lowest;
    float highest;
  };

  // The region's finite depths, in order, and their range.
  static SoilDepths collect_finite(const cv::Mat& depth_mm, const cv::Rect& roi,
                                   std::vector<float>& depths) {
    // Never shrunk, so no frame after the first allocates or clears it; one slot more
    // for the store after the last finite depth.
    const auto slots = static_cast<std::size_t>(roi.area()) + 1;
    if (depths.size() < slots) depths.resize(slots);
    FiniteDepths found{depths.data(), kLargest, -kLargest};
    for (int row = roi.y; row < roi.y + roi.height; ++row) {
      found = collect_finite_row(depth_mm.ptr<float>(row) + roi.x, roi.width, found);
    }
    return {{depths.data(), static_cast<std::size_t>(found.end - depths.data())},
            found.lowest,
            found.highest};
  }

  // The trimmed mean, the median and the spread from one histogram of the depths and one
  // of their deviations from the median, which lie between 0 and those of the extremes.
  void measure(const SoilDepths& depths, GroundDistance& out) const {
    thread_local RankSelection ranks;
    ranks.index(depths.mm, depths.lowest, depths.highest);
    const double median_mm = ranks.median();
    const double distance_mm = statistic_ == Statistic::kMedian
                                   ? median_mm
                                   : trimmed_mean(ranks, depths.mm.size(), trim_fraction_);
    replace_by_deviations(depths.mm, median_mm);
    ranks.index(
        depths.mm, 0.0f,
        std::max(deviation(depths.lowest, median_mm), deviation(depths.highest, median_mm)));
    out.spread_mm = kMadToSigma * ranks.median();
    out.distance_mm = distance_mm;
    out.valid = true;
    out.confidence = confidence(out.soil_fraction, out.spread_mm);
  }

  // The soil of `roi` beyond a level ground at `distance_mm`, by quadrant around the
  // region's centre (pixel centres at +0.5).
  SoilBeyond soil_beyond(const cv::Mat& soil_mm, const cv::Rect& roi, double distance_mm) const {
    SoilBeyond beyond = gates_.soil_beyond(depth_noise_mm(soil_mm, roi, kBeyondNoiseFloorMm));
    const cv::Point2d centre(roi.x + 0.5 * roi.width, roi.y + 0.5 * roi.height);
    for (int row = roi.y; row < roi.y + roi.height; row += kBeyondSampleStep) {
      const float* depth = soil_mm.ptr<float>(row);
      for (int col = roi.x; col < roi.x + roi.width; col += kBeyondSampleStep) {
        if (std::isfinite(depth[col])) {
          beyond.add(col + 0.5 - centre.x, row + 0.5 - centre.y, depth[col] - distance_mm);
        }
      }
    }
    return beyond;
  }

  const RegionOfInterest region_;
  const Statistic statistic_;
  const double trim_fraction_;
  const SoilRequirement requirement_;
  const PlausibilityGates gates_;
  const Logger log_;
  std::once_flag clipping_logged_;
  MessagePool<GroundDistance> outputs_;
};

}  // namespace

StageDescriptor describe_ground_distance() {
  StageDescriptor d;
  d.type = "estimation.ground_distance";
  d.summary = "ground distance = robust statistic of the soil depths in a region of interest";
  d.inputs = {
      PortSpec::of<DepthImage>("soil_depth", "depth of the soil pixels, NaN elsewhere"),
      PlausibilityGates::color_port(),
  };
  d.outputs = {PortSpec::of<GroundDistance>(
      "distance", "distance, validity, soil fraction, spread (1.4826 MAD), confidence")};
  d.params = {
      roi_param(RegionOfInterest::Whole::kMiddleHalf),
      ParamSpec::choice("statistic", {"median", "trimmed_mean"}, "median")
          .describe("how the soil depths become one distance"),
      ParamSpec::number("trim_fraction", 0.2)
          .range(0, 0.45)
          .describe("trimmed_mean: fraction of the depths dropped at each end"),
      min_soil_fraction_param(),
      min_soil_pixels_param(),
  };
  const auto gates = PlausibilityGates::params();
  d.params.insert(d.params.end(), gates.begin(), gates.end());
  d.concurrency = Concurrency::kParallel;
  d.create = factory<GroundDistanceEstimator>();
  return d;
}

TILTH_STAGE(describe_ground_distance());

}  // namespace tilth::estimation
