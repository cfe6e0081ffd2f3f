// The plane is depth = a u + b v + c in pixel coordinates: exact for a flat ground seen
// by an undistorted camera looking straight down, and within a fraction of a millimetre
// for the tilts a mounting allows (the local surface takes up the rest).
//
// RANSAC draws its three points from the farthest third of the sampled depths (soil, if
// any is visible, lies there) and scores a plane by the points within kBand of it minus
// the points more than kBand beyond it: a plane through the middle of a residue layer has
// many points beyond it, the soil has none.
#include "soil_surface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace tilth::segmentation {
namespace {

constexpr int kSampleStepPx = 8;
constexpr int kHypotheses = 200;
constexpr std::size_t kScoreStep = 2;  // hypotheses are scored on every second point
constexpr int kRefinements = 5;
constexpr int kLocalPasses = 3;
constexpr double kBandMm = 1.5;  // three standard deviations of the median-filtered ToF noise
constexpr std::size_t kMinPoints = 30;
// Any fixed value: the same frame always gives the same surface.
constexpr std::uint32_t kSeed = 20240611;

struct Point {
  double u;
  double v;
  double depth;
};

struct Plane {
  double a;
  double b;
  double c;
  double at(double u, double v) const { return a * u + b * v + c; }
};

std::optional<Plane> through(const Point& p, const Point& q, const Point& r) {
  const cv::Matx33d m(p.u, p.v, 1, q.u, q.v, 1, r.u, r.v, 1);
  if (std::abs(cv::determinant(m)) < 1.0) return std::nullopt;  // px^2: nearly collinear
  const cv::Vec3d abc = m.solve(cv::Vec3d(p.depth, q.depth, r.depth), cv::DECOMP_LU);
  return Plane{abc[0], abc[1], abc[2]};
}

std::optional<Plane> least_squares(const std::vector<Point>& points, const Plane& near) {
  cv::Matx33d normal = cv::Matx33d::zeros();
  cv::Vec3d right(0, 0, 0);
  std::size_t used = 0;
  for (const Point& p : points) {
    if (std::abs(p.depth - near.at(p.u, p.v)) > kBandMm) continue;
    const cv::Vec3d row(p.u, p.v, 1);
    normal += row * row.t();
    right += p.depth * row;
    ++used;
  }
  if (used < 3) return std::nullopt;
  cv::Vec3d abc;
  if (!cv::solve(normal, right, abc, cv::DECOMP_CHOLESKY)) return std::nullopt;
  return Plane{abc[0], abc[1], abc[2]};
}

std::optional<Plane> ransac(const std::vector<Point>& points) {
  std::vector<double> depths(points.size());
  std::transform(points.begin(), points.end(), depths.begin(),
                 [](const Point& p) { return p.depth; });
  auto third = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() * 2 / 3);
  std::nth_element(depths.begin(), third, depths.end());
  std::vector<const Point*> far;
  for (const Point& p : points) {
    if (p.depth >= *third) far.push_back(&p);
  }
  std::mt19937 rng(kSeed);
  std::uniform_int_distribution<std::size_t> pick(0, far.size() - 1);
  std::optional<Plane> best;
  long best_score = std::numeric_limits<long>::min();
  for (int hypothesis = 0; hypothesis < kHypotheses; ++hypothesis) {
    const std::optional<Plane> plane = through(*far[pick(rng)], *far[pick(rng)], *far[pick(rng)]);
    if (!plane) continue;
    long score = 0;
    for (std::size_t i = 0; i < points.size(); i += kScoreStep) {
      const double beyond = points[i].depth - plane->at(points[i].u, points[i].v);
      score += beyond > kBandMm ? -1 : (beyond >= -kBandMm ? 1 : 0);
    }
    if (score > best_score) {
      best_score = score;
      best = plane;
    }
  }
  for (int refinement = 0; best && refinement < kRefinements; ++refinement) {
    const std::optional<Plane> better = least_squares(points, *best);
    if (!better) break;
    best = better;
  }
  return best;
}

// The RANSAC plane through the depths of every kSampleStepPx-th supported pixel, unless
// too few are supported.
std::optional<Plane> farthest_plane(const cv::Mat& depth, const cv::Mat& support) {
  thread_local std::vector<Point> points;
  points.clear();
  for (int row = kSampleStepPx / 2; row < depth.rows; row += kSampleStepPx) {
    const auto* d = depth.ptr<float>(row);
    const auto* soil = support.ptr<std::uint8_t>(row);
    for (int col = kSampleStepPx / 2; col < depth.cols; col += kSampleStepPx) {
      if (soil[col] != 0) points.push_back({double(col), double(row), d[col]});
    }
  }
  return points.size() < kMinPoints ? std::nullopt : ransac(points);
}

// The envelope on the half-resolution grid: a morphological closing of the depth of the
// pixels that may be soil (the farthest depth within the window, then the nearest of
// those). Residue narrower than the window is gone from it; ground that slopes, curves
// gently or steps over more than a window is kept as it is. NaN where no pixel within the
// window may be soil.
void envelope(const cv::Mat& depth, const cv::Mat& support, double window_px, cv::Mat& surface) {
  constexpr float kNoSurface = std::numeric_limits<float>::max();
  thread_local cv::Mat farthest, none;
  farthest.create(depth.size(), CV_32FC1);
  farthest.setTo(0);
  depth.copyTo(farthest, support);
  const int side = 2 * static_cast<int>(std::lround(window_px / 4)) + 1;  // odd, half scale
  const cv::Mat window = cv::getStructuringElement(cv::MORPH_RECT, {side, side});
  cv::dilate(farthest, surface, window);
  cv::compare(surface, 0, none, cv::CMP_LE);
  surface.setTo(kNoSurface, none);
  cv::erode(surface, surface, window);
  cv::compare(surface, kNoSurface, none, cv::CMP_EQ);
  surface.setTo(std::numeric_limits<float>::quiet_NaN(), none);
}

// The local surface, on every second pixel of every second row (it varies over several
// pixels, and this is a quarter of the work), starting from the plane. Each pass: the
// soil is what lies no higher than height_mm above the current surface; the new surface
// is the Gaussian-weighted mean of its depths, or stays where there is too little soil
// nearby (under a hundredth of the kernel's weight).
void follow_relief(const std::optional<Plane>& plane, double envelope_px, const cv::Mat& depth,
                   const cv::Mat& support, double height_mm, double surface_px, cv::Mat& surface) {
  thread_local cv::Mat depth_half, support_half, surface_half, height, soil, weight, weighted;
  cv::resize(depth, depth_half, {}, 0.5, 0.5, cv::INTER_NEAREST);
  cv::resize(support, support_half, {}, 0.5, 0.5, cv::INTER_NEAREST);
  if (plane) {
    surface_half.create(depth_half.size(), CV_32FC1);
    for (int row = 0; row < surface_half.rows; ++row) {
      auto* s = surface_half.ptr<float>(row);
      for (int col = 0; col < surface_half.cols; ++col) {
        s[col] = static_cast<float>(plane->at(2 * col, 2 * row));
      }
    }
  } else {
    envelope(depth_half, support_half, envelope_px, surface_half);
  }
  const double sigma = surface_px / 2;
  for (int pass = 0; surface_px > 0 && pass < kLocalPasses; ++pass) {
    cv::subtract(surface_half, depth_half, height);
    cv::compare(height, height_mm, soil, cv::CMP_LT);
    cv::bitwise_and(soil, support_half, soil);
    soil.convertTo(weight, CV_32F, 1.0 / 255);
    cv::multiply(depth_half, weight, weighted);
    cv::GaussianBlur(weighted, weighted, {0, 0}, sigma);
    cv::GaussianBlur(weight, weight, {0, 0}, sigma);
    for (int row = 0; row < surface_half.rows; ++row) {
      auto* s = surface_half.ptr<float>(row);
      const auto* sum = weighted.ptr<float>(row);
      const auto* w = weight.ptr<float>(row);
      for (int col = 0; col < surface_half.cols; ++col) {
        if (w[col] > 0.01f) s[col] = sum[col] / w[col];
      }
    }
  }
  cv::resize(surface_half, surface, depth.size(), 0, 0, cv::INTER_LINEAR);
}

}  // namespace

SoilSurface::SoilSurface(double height_mm, double surface_px, double envelope_px)
    : height_mm_(height_mm), surface_px_(surface_px), envelope_px_(envelope_px) {}

void SoilSurface::heights(const cv::Mat& depth_mm, const cv::Mat& missing,
                          const cv::Mat& candidates, cv::Mat& height_mm) const {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  thread_local cv::Mat depth, no_depth, support, surface;
  // A 3x3 median: a third of the ToF noise, and single dropouts (0 here) do not count;
  // where most neighbours have none, neither has the pixel.
  depth_mm.copyTo(depth);
  depth.setTo(0, missing);
  cv::medianBlur(depth, depth, 3);
  cv::compare(depth, 0, no_depth, cv::CMP_LE);
  cv::bitwise_or(no_depth, missing, no_depth);
  cv::bitwise_and(candidates, ~no_depth, support);

  if (envelope_px_ > 0) {
    follow_relief(std::nullopt, envelope_px_, depth, support, height_mm_, surface_px_, surface);
  } else {
    const std::optional<Plane> plane = farthest_plane(depth, support);
    height_mm.create(depth_mm.size(), CV_32FC1);
    if (!plane) {
      height_mm.setTo(kNaN);
      return;
    }
    if (surface_px_ <= 0) {
      surface.create(depth.size(), CV_32FC1);
      for (int row = 0; row < depth.rows; ++row) {
        auto* s = surface.ptr<float>(row);
        for (int col = 0; col < depth.cols; ++col) s[col] = static_cast<float>(plane->at(col, row));
      }
    } else {
      follow_relief(plane, 0.0, depth, support, height_mm_, surface_px_, surface);
    }
  }
  cv::subtract(surface, depth, height_mm);
  height_mm.setTo(kNaN, no_depth);
}

ParamSpec height_mm_param() {
  return ParamSpec::number("height_mm", 3.0)
      .range(0.5, 100)
      .in_unit("mm")
      .describe("pixels more than this above the fitted soil surface are residue");
}

ParamSpec surface_px_param() {
  return ParamSpec::number("surface_px", 3.0)
      .range(0, 100)
      .in_unit("px")
      .describe("the soil surface follows relief at this scale (Gaussian sigma); 0 = a plane");
}

ParamSpec envelope_px_param() {
  return ParamSpec::number("envelope_px", 0.0)
      .range(0, 400)
      .in_unit("px")
      .describe(
          "0: the surface starts from a RANSAC plane through the farthest depths; > 0: "
          "from their envelope over this window (steps, ridges; no pile wider than it)");
}

}  // namespace tilth::segmentation
