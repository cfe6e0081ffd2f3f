#include "edge_alignment.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <opencv2/imgproc.hpp>

namespace tilth::calibrate {
namespace {

constexpr int kWindow = 2 * kSearchRadiusPx + 1;
constexpr int kBins = static_cast<int>(kHistogramRangePx / kHistogramBinPx) + 1;

}  // namespace

const char* to_string(NearSide side) { return side == NearSide::kBrighter ? "brighter" : "darker"; }

DirectedDistances::DirectedDistances(const cv::Mat& color_edges) {
  CV_Assert(color_edges.type() == CV_8UC1);
  edge_pixels_ = static_cast<std::uint64_t>(cv::countNonZero(color_edges));
  for (int sector = 0; sector < kSectors; ++sector) {
    cv::Mat near(color_edges.size(), CV_8UC1, cv::Scalar(0));
    for (const int neighbour : {kSectors - 1, 0, 1}) {
      near.setTo(255, color_edges == 1 + (sector + neighbour) % kSectors);
    }
    cv::distanceTransform(near == 0, maps_[sector], cv::DIST_L2, cv::DIST_MASK_PRECISE);
  }
}

ShiftedDistances::ShiftedDistances()
    : capped_sum_(kWindow * kWindow, 0.0),
      count_(kWindow * kWindow, 0),
      histogram_(kWindow * kWindow * kBins, 0) {}

std::size_t ShiftedDistances::index(cv::Point shift) const {
  CV_Assert(std::abs(shift.x) <= kSearchRadiusPx && std::abs(shift.y) <= kSearchRadiusPx);
  return static_cast<std::size_t>((shift.y + kSearchRadiusPx) * kWindow + shift.x +
                                  kSearchRadiusPx);
}

void ShiftedDistances::add_frame(const cv::Mat& depth_edges, const DirectedDistances& color,
                                 NearSide side) {
  CV_Assert(depth_edges.type() == CV_8UC1 && depth_edges.size() == color.towards(0).size());
  color_edge_pixels_ += color.edge_pixels();
  const int turn = side == NearSide::kBrighter ? 0 : kSectors / 2;
  std::vector<cv::Point> edges;
  cv::findNonZero(depth_edges, edges);
  // Each depth edge with the distances to the colour edges it may match.
  std::vector<const cv::Mat*> distances;
  distances.reserve(edges.size());
  for (const cv::Point& edge : edges) {
    distances.push_back(&color.towards((depth_edges.at<std::uint8_t>(edge) - 1 + turn) % kSectors));
  }
  for (int dy = -kSearchRadiusPx; dy <= kSearchRadiusPx; ++dy) {
    for (int dx = -kSearchRadiusPx; dx <= kSearchRadiusPx; ++dx) {
      const std::size_t at = index({dx, dy});
      std::uint64_t* bins = &histogram_[at * kBins];
      double sum = 0.0;
      std::uint64_t count = 0;
      for (std::size_t i = 0; i < edges.size(); ++i) {
        const int u = edges[i].x + dx;
        const int v = edges[i].y + dy;
        if (u < 0 || v < 0 || u >= depth_edges.cols || v >= depth_edges.rows) continue;
        const float d = distances[i]->at<float>(v, u);
        sum += std::min(static_cast<double>(d), kTruncationPx);
        ++count;
        ++bins[std::min(kBins - 1,
                        static_cast<int>(std::min(static_cast<double>(d), kHistogramRangePx) /
                                         kHistogramBinPx))];
      }
      capped_sum_[at] += sum;
      count_[at] += count;
    }
  }
}

void ShiftedDistances::add(const ShiftedDistances& other) {
  for (std::size_t i = 0; i < capped_sum_.size(); ++i) {
    capped_sum_[i] += other.capped_sum_[i];
    count_[i] += other.count_[i];
  }
  for (std::size_t i = 0; i < histogram_.size(); ++i) histogram_[i] += other.histogram_[i];
  color_edge_pixels_ += other.color_edge_pixels_;
}

std::uint64_t ShiftedDistances::depth_edge_pixels() const { return count_[index({0, 0})]; }

double ShiftedDistances::cost(cv::Point shift) const {
  const std::size_t at = index(shift);
  return count_[at] == 0 ? kTruncationPx : capped_sum_[at] / static_cast<double>(count_[at]);
}

DistanceQuantiles ShiftedDistances::quantiles(cv::Point shift) const {
  const std::size_t at = index(shift);
  const std::uint64_t* bins = &histogram_[at * kBins];
  // The upper end of the bin where the cumulative count reaches the fraction.
  const auto quantile = [&](double fraction) {
    const double wanted = fraction * static_cast<double>(count_[at]);
    std::uint64_t seen = 0;
    for (int bin = 0; bin < kBins; ++bin) {
      seen += bins[bin];
      if (static_cast<double>(seen) >= wanted) return (bin + 1) * kHistogramBinPx;
    }
    return kHistogramRangePx;
  };
  if (count_[at] == 0) return {kHistogramRangePx, kHistogramRangePx};
  return {quantile(0.5), quantile(0.9)};
}

cv::Point ShiftedDistances::best_shift() const {
  cv::Point best{0, 0};
  for (int dy = -kSearchRadiusPx; dy <= kSearchRadiusPx; ++dy) {
    for (int dx = -kSearchRadiusPx; dx <= kSearchRadiusPx; ++dx) {
      const double c = cost({dx, dy});
      const double b = cost(best);
      if (c < b || (c == b && dx * dx + dy * dy < best.dot(best))) best = {dx, dy};
    }
  }
  return best;
}

cv::Point2d ShiftedDistances::best_offset() const {
  const cv::Point best = best_shift();
  const auto refine = [&](cv::Point step) {
    const cv::Point before = best - step;
    const cv::Point after = best + step;
    if (std::abs(before.x) > kSearchRadiusPx || std::abs(before.y) > kSearchRadiusPx ||
        std::abs(after.x) > kSearchRadiusPx || std::abs(after.y) > kSearchRadiusPx) {
      return 0.0;
    }
    const double low = cost(before);
    const double mid = cost(best);
    const double high = cost(after);
    const double rise = std::max(low, high) - mid;
    return rise > 0.0 ? std::clamp((low - high) / (2.0 * rise), -0.5, 0.5) : 0.0;
  };
  return {best.x + refine({1, 0}), best.y + refine({0, 1})};
}

double ShiftedDistances::contrast() const {
  std::vector<double> costs;
  costs.reserve(kWindow * kWindow);
  for (int dy = -kSearchRadiusPx; dy <= kSearchRadiusPx; ++dy) {
    for (int dx = -kSearchRadiusPx; dx <= kSearchRadiusPx; ++dx) costs.push_back(cost({dx, dy}));
  }
  const auto middle = costs.begin() + static_cast<std::ptrdiff_t>(costs.size() / 2);
  std::nth_element(costs.begin(), middle, costs.end());
  return *middle > 0.0 ? 1.0 - cost(best_shift()) / *middle : 0.0;
}

}  // namespace tilth::calibrate
