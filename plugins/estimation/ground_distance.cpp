// estimation.ground_distance: the paper's last step (section 2.4) -- one ground distance
// from the soil depths left in a region of interest, as a robust statistic.
//
//   soil_depth ──► finite depths in roi ──► enough soil? ──► median | trimmed mean ──► distance
//                                               └── no ──► invalid, with the reason
//
// Invariant: an invalid measurement carries distance_mm 0 and confidence 0; too little
// visible soil is never turned into a guess.
//
//   "estimate": {"type": "estimation.ground_distance",
//                "params": {"roi": {"x": 160, "y": 120, "width": 320, "height": 240},
//                           "statistic": "median", "min_soil_fraction": 0.05}}
#include <algorithm>
#include <cmath>
#include <mutex>
#include <numeric>
#include <span>
#include <vector>

#include "estimators.h"
#include "soil_region.h"
#include "tilth/error.h"
#include "tilth/message_pool.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/plugin.h"

namespace tilth::estimation {
namespace {

// Scales the median absolute deviation to the standard deviation of normal data.
constexpr double kMadToSigma = 1.4826;

// nth_element, not a sort: linear time. Reorders `values`.
double median_in_place(std::span<float> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  if (values.size() % 2 == 1) return *middle;
  const float below = *std::max_element(values.begin(), middle);
  return 0.5 * (static_cast<double>(below) + static_cast<double>(*middle));
}

// The mean of what is left after dropping `trim_fraction` of the values at each end.
double trimmed_mean_in_place(std::span<float> values, double trim_fraction) {
  const auto cut = static_cast<std::ptrdiff_t>(trim_fraction * static_cast<double>(values.size()));
  const auto first = values.begin() + cut;
  const auto last = values.end() - cut;
  if (cut > 0) {
    std::nth_element(values.begin(), first, values.end());
    std::nth_element(first, last, values.end());  // only ranks >= cut remain to split
  }
  return std::accumulate(first, last, 0.0) / static_cast<double>(last - first);
}

double spread_in_place(std::span<float> values, double median) {
  for (float& value : values) value = static_cast<float>(std::abs(value - median));
  return kMadToSigma * median_in_place(values);
}

enum class Statistic { kMedian, kTrimmedMean };

class GroundDistanceEstimator final : public Transform {
 public:
  explicit GroundDistanceEstimator(const StageContext& context)
      : region_(context.params.json("roi")),
        statistic_(context.params.string("statistic") == "median" ? Statistic::kMedian
                                                                  : Statistic::kTrimmedMean),
        trim_fraction_(context.params.number("trim_fraction")),
        requirement_(soil_requirement(context.params)),
        max_spread_mm_(context.params.number("max_spread_mm")),
        log_(context.log) {}

  void process(Frame& frame) override {
    const auto& soil = frame.input<DepthImage>(0);
    if (soil.mm.type() != CV_32FC1) {
      throw Error("input 'soil_depth': expected a CV_32FC1 image in mm, got type " +
                  std::to_string(soil.mm.type()));
    }
    const cv::Rect roi = region_.on(soil.mm.size());
    if (region_.clipped_on(soil.mm.size())) {
      std::call_once(clipping_logged_,
                     [&] { log_.warning(region_.clipping_note(soil.mm.size())); });
    }

    thread_local std::vector<float> depths;
    collect_finite(soil.mm, roi, depths);
    const auto message = outputs_.acquire();
    GroundDistance& out = *message;
    out = GroundDistance{};  // a reused message keeps its string's buffer
    out.soil_pixels = static_cast<std::int64_t>(depths.size());
    out.soil_fraction = static_cast<double>(depths.size()) / roi.area();
    out.invalid_reason = requirement_.shortfall(out.soil_pixels, roi.area());
    if (out.invalid_reason.empty()) measure(depths, out);
    frame.set_output(0, message);
  }

 private:
  static void collect_finite(const cv::Mat& depth_mm, const cv::Rect& roi,
                             std::vector<float>& depths) {
    depths.clear();
    depths.reserve(static_cast<std::size_t>(roi.area()));
    for (int row = roi.y; row < roi.y + roi.height; ++row) {
      const float* depth = depth_mm.ptr<float>(row);
      for (int col = roi.x; col < roi.x + roi.width; ++col) {
        if (std::isfinite(depth[col])) depths.push_back(depth[col]);
      }
    }
  }

  void measure(std::span<float> depths, GroundDistance& out) const {
    // The trimmed mean first: the median and the spread reorder and overwrite the values.
    const double distance_mm =
        statistic_ == Statistic::kTrimmedMean ? trimmed_mean_in_place(depths, trim_fraction_) : 0.0;
    const double median_mm = median_in_place(depths);
    out.spread_mm = spread_in_place(depths, median_mm);
    if (max_spread_mm_ > 0 && out.spread_mm > max_spread_mm_) {
      out.invalid_reason = "soil depths spread too widely: " + one_decimal(out.spread_mm) +
                           " mm > " + one_decimal(max_spread_mm_) + " mm (not one surface?)";
      return;
    }
    out.distance_mm = statistic_ == Statistic::kMedian ? median_mm : distance_mm;
    out.valid = true;
    out.confidence = confidence(out.soil_fraction, out.spread_mm);
  }

  const RegionOfInterest region_;
  const Statistic statistic_;
  const double trim_fraction_;
  const SoilRequirement requirement_;
  const double max_spread_mm_;
  const Logger log_;
  std::once_flag clipping_logged_;
  MessagePool<GroundDistance> outputs_;
};

}  // namespace

StageDescriptor describe_ground_distance() {
  StageDescriptor d;
  d.type = "estimation.ground_distance";
  d.summary = "ground distance = robust statistic of the soil depths in a region of interest";
  d.inputs = {PortSpec::of<DepthImage>("soil_depth", "depth of the soil pixels, NaN elsewhere")};
  d.outputs = {PortSpec::of<GroundDistance>(
      "distance", "distance, validity, soil fraction, spread (1.4826 MAD), confidence")};
  d.params = {
      roi_param(),
      ParamSpec::choice("statistic", {"median", "trimmed_mean"}, "median")
          .describe("how the soil depths become one distance"),
      ParamSpec::number("trim_fraction", 0.2)
          .range(0, 0.45)
          .describe("trimmed_mean: fraction of the depths dropped at each end"),
      min_soil_fraction_param(),
      min_soil_pixels_param(),
      ParamSpec::number("max_spread_mm", 0.0)
          .range(0, std::nullopt)
          .in_unit("mm")
          .describe("above this spread (1.4826 MAD) the measurement is invalid; 0 = no limit"),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<GroundDistanceEstimator>();
  return d;
}

TILTH_STAGE(describe_ground_distance());

}  // namespace tilth::estimation
