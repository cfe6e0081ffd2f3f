// segmentation.lab_clusters: residue as one of two colour clusters found in the frame
// itself (k-means, k = 2), in CIE Lab with the lightness divided out.
//
//   color ──► mean over a (2r+1)^2 box ──► Lab ──► (a*/L*, b*/L*) ──► k-means on the
//   trusted pixels of every third row and column, started from the halves below and above
//   their median hue angle ──► centres far enough apart? ──► the more yellow centre (larger hue
//   angle atan2(b*, a*)) is residue; each pixel to its nearest centre ──► despeckle ──► dilate
//                         └── no ──► each pixel by its hue angle: 78-258 deg is residue
//
// Invariant: the same frame always gives the same mask (the start is a function of the
// frame, no random seed). Dividing by L* makes the features nearly blind to how brightly a
// surface is lit, so the clusters are straw and soil, not sun and shadow.
//
//   "segment": {"type": "segmentation.lab_clusters"}
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "one_material_notice.h"
#include "residue_output.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

// Below this lightness the ratio would amplify sensor noise without bound.
constexpr float kMinLightness = 10.0f;
// Centres closer than this (in 100 * a*/L*, b*/L*) are one material: straw and soil lie
// about 25 apart, a frame of one material splits into halves about 5 apart
// (docs/segmentation-variants.md).
constexpr double kMinSeparation = 12.0;
// For one material: straw lies at hue angles of 85-95 deg, soils at 50-72 deg; residue is
// the half-plane of hue angles from this one to 180 deg more.
constexpr double kResidueHueDeg = 78.0;
constexpr int kMaxIterations = 30;
// Clustering every third pixel of every third row: some 30 000 points.
constexpr int kSampleStepPx = 3;

double hue_deg(const cv::Vec2f& feature) {
  return std::atan2(feature[1], feature[0]) * 180.0 / CV_PI;
}

// (100 a*/L*, 100 b*/L*) of each pixel's mean colour.
void chroma_features(const cv::Mat& bgr, int smoothing_px, cv::Mat& features) {
  thread_local cv::Mat scaled, lab;
  bgr.convertTo(scaled, CV_32FC3, 1.0 / 255);
  if (smoothing_px > 0) {
    const int side = 2 * smoothing_px + 1;
    cv::blur(scaled, scaled, {side, side}, {-1, -1}, cv::BORDER_REFLECT);
  }
  cv::cvtColor(scaled, lab, cv::COLOR_BGR2Lab);
  features.create(bgr.size(), CV_32FC2);
  for (int row = 0; row < bgr.rows; ++row) {
    const auto* in = lab.ptr<cv::Vec3f>(row);
    auto* out = features.ptr<cv::Vec2f>(row);
    for (int col = 0; col < bgr.cols; ++col) {
      const float scale = 100.0f / std::max(in[col][0], kMinLightness);
      out[col] = {in[col][1] * scale, in[col][2] * scale};
    }
  }
}

// A line in the feature plane: a point is on its residue side when side(point) >= 0.
struct Boundary {
  float a;
  float b;
  float c;
  bool residue(const cv::Vec2f& p) const { return a * p[0] + b * p[1] + c >= 0; }
};

// Hue angles from `degrees` to `degrees` + 180: the yellows, greens and blues.
Boundary hue_at_least(double degrees) {
  const double radians = degrees * CV_PI / 180.0;
  return {static_cast<float>(-std::sin(radians)), static_cast<float>(std::cos(radians)), 0.0f};
}

struct Clusters {
  cv::Vec2f soil;
  cv::Vec2f residue;
  double separation() const { return cv::norm(residue - soil); }
  // Nearer the residue centre than the soil centre.
  Boundary boundary() const {
    const cv::Vec2f direction = residue - soil;
    const cv::Vec2f middle = 0.5f * (residue + soil);
    return {direction[0], direction[1], -direction.dot(middle)};
  }
};

float squared_distance(const cv::Vec2f& p, const cv::Vec2f& q) {
  const cv::Vec2f d = p - q;
  return d.dot(d);
}

// Lloyd's k-means with two centres, started from the halves of the points below and
// above their median hue angle. Empty when the points do not form two groups.
std::optional<Clusters> two_means(const std::vector<cv::Vec2f>& points) {
  if (points.size() < 2) return std::nullopt;
  thread_local std::vector<double> hues;
  hues.resize(points.size());
  std::transform(points.begin(), points.end(), hues.begin(), hue_deg);
  thread_local std::vector<double> ordered;
  ordered = hues;
  auto middle = ordered.begin() + static_cast<std::ptrdiff_t>(ordered.size() / 2);
  std::nth_element(ordered.begin(), middle, ordered.end());

  thread_local std::vector<std::uint8_t> upper;
  upper.resize(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) upper[i] = hues[i] >= *middle;
  cv::Vec2f centres[2];
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    cv::Vec2d sums[2] = {{0, 0}, {0, 0}};
    std::size_t counts[2] = {0, 0};
    for (std::size_t i = 0; i < points.size(); ++i) {
      sums[upper[i]] += cv::Vec2d(points[i]);
      ++counts[upper[i]];
    }
    if (counts[0] == 0 || counts[1] == 0) return std::nullopt;  // one colour throughout
    centres[0] = sums[0] / static_cast<double>(counts[0]);
    centres[1] = sums[1] / static_cast<double>(counts[1]);
    bool changed = false;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const std::uint8_t nearer =
          squared_distance(points[i], centres[1]) < squared_distance(points[i], centres[0]);
      changed = changed || nearer != upper[i];
      upper[i] = nearer;
    }
    if (!changed) break;
  }
  const bool first_is_residue = hue_deg(centres[0]) > hue_deg(centres[1]);
  return Clusters{centres[first_is_residue ? 1 : 0], centres[first_is_residue ? 0 : 1]};
}

class LabClusters final : public Transform {
 public:
  explicit LabClusters(const StageContext& context)
      : smoothing_px_(static_cast<int>(context.params.integer("smoothing_px"))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        output_(context.params),
        notice_(context.log) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat features, residue;
    thread_local std::vector<cv::Vec2f> sample;
    chroma_features(in.bgr, smoothing_px_, features);

    sample.clear();
    for (int row = 0; row < features.rows; row += kSampleStepPx) {
      const auto* feature = features.ptr<cv::Vec2f>(row);
      const auto* skip = in.untrusted.ptr<std::uint8_t>(row);
      for (int col = 0; col < features.cols; col += kSampleStepPx) {
        if (skip[col] == 0) sample.push_back(feature[col]);
      }
    }
    const std::optional<Clusters> clusters = two_means(sample);
    const double separation = clusters ? clusters->separation() : 0.0;
    const bool one_material = separation < kMinSeparation;
    notice_.report(frame.info().frame_id, one_material,
                   "cluster separation " + std::to_string(static_cast<int>(separation)));

    const Boundary boundary = one_material ? hue_at_least(kResidueHueDeg) : clusters->boundary();
    residue.create(features.size(), CV_8UC1);
    for (int row = 0; row < features.rows; ++row) {
      const auto* feature = features.ptr<cv::Vec2f>(row);
      auto* out = residue.ptr<std::uint8_t>(row);
      for (int col = 0; col < features.cols; ++col) {
        out[col] = boundary.residue(feature[col]) ? ResidueMask::kResidue : ResidueMask::kSoil;
      }
    }
    output_.emit(frame, in.area, residue, in.untrusted, in.unknown, in.depth_mm);
  }

 private:
  const int smoothing_px_;
  const int min_value_;
  ResidueOutput output_;
  OneMaterialNotice notice_;
};

}  // namespace

StageDescriptor describe_lab_clusters() {
  StageDescriptor d;
  d.type = "segmentation.lab_clusters";
  d.summary = "residue mask from two colour clusters (k-means) in Lab, lightness divided out";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      smoothing_px_param(), dilation_px_param(), segmented_roi_param(),
      speckle_px_param(1),  min_value_param(),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<LabClusters>();
  return d;
}

TILTH_STAGE(describe_lab_clusters());

}  // namespace tilth::segmentation
