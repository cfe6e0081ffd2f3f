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
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "depth_noise/depth_noise.h"

namespace tilth::segmentation {
namespace {

constexpr int kSampleStepPx = 8;
// The plane beside the envelope only bounds how high the envelope may ride, within a
// residue height: a quarter of the points will do, at a quarter of the cost.
constexpr int kBesideEnvelopeStepPx = 16;
constexpr int kHypotheses = 200;
constexpr std::size_t kScoreStep = 2;  // hypotheses are scored on every second point
constexpr int kRefinements = 5;
constexpr int kLocalPasses = 3;
constexpr double kBandMm = 1.5;  // three standard deviations of the median-filtered ToF noise
// The residue height per millimetre of the depth's noise: 1.7 standard deviations of the
// 3x3 median, whose noise is 0.42 of the depth's (Gaussian noise), so that noise lifts
// under 5 % of the soil above it. At three times the simulator's ToF noise soil lifted
// above 3 mm was taken for residue, and the soil left read 0.8 mm far (docs/accuracy.md).
constexpr double kHeightPerNoise = 1.7 * 0.42;
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

// `use` ? a : b by their bits: GCC vectorises it where it declines a select of floats on a
// byte's test or after a division.
inline float pick(bool use, float a, float b) {
  const std::uint32_t mask = 0u - static_cast<std::uint32_t>(use);
  return std::bit_cast<float>((std::bit_cast<std::uint32_t>(a) & mask) |
                              (std::bit_cast<std::uint32_t>(b) & ~mask));
}

// A pixel may support the surface when it is a candidate and has a (median) depth.
bool supports(float depth, std::uint8_t missing, std::uint8_t candidate) {
  return (candidate != 0) & (missing == 0) & (depth > 0);  // `&`: no branch, vectorised
}

// The RANSAC plane through the depths of every `step`-th supported pixel, unless
// too few are supported.
std::optional<Plane> farthest_plane(const cv::Mat& depth, const cv::Mat& missing,
                                    const cv::Mat& candidates, int step) {
  thread_local std::vector<Point> points;
  points.clear();
  for (int row = step / 2; row < depth.rows; row += step) {
    const auto* d = depth.ptr<float>(row);
    const auto* none = missing.ptr<std::uint8_t>(row);
    const auto* candidate = candidates.ptr<std::uint8_t>(row);
    for (int col = step / 2; col < depth.cols; col += step) {
      if (supports(d[col], none[col], candidate[col]))
        points.push_back({double(col), double(row), d[col]});
    }
  }
  return points.size() < kMinPoints ? std::nullopt : ransac(points);
}

// The depth of every second pixel of every second row, and 0 where it may not support
// the surface.
void half_support(const cv::Mat& depth, const cv::Mat& missing, const cv::Mat& candidates,
                  cv::Mat& supported) {
  supported.create((depth.rows + 1) / 2, (depth.cols + 1) / 2, CV_32FC1);
  for (int row = 0; row < supported.rows; ++row) {
    const auto* d = depth.ptr<float>(2 * row);
    const auto* none = missing.ptr<std::uint8_t>(2 * row);
    const auto* candidate = candidates.ptr<std::uint8_t>(2 * row);
    auto* out = supported.ptr<float>(row);
    for (int col = 0; col < supported.cols; ++col) {
      const int at = 2 * col;
      out[col] = pick(supports(d[at], none[at], candidate[at]), d[at], 0.0f);
    }
  }
}

// The envelope of the supported depths (0: none): a morphological closing (the farthest
// depth within the window, then the nearest of those). Residue narrower than the window
// is gone from it; ground that slopes, curves gently or steps over more than a window is
// kept as it is. NaN where no pixel within the window may be soil.
void envelope(const cv::Mat& supported, const cv::Mat& window, cv::Mat& surface) {
  constexpr float kNoSurface = std::numeric_limits<float>::max();
  thread_local cv::Mat farthest;
  cv::dilate(supported, farthest, window);
  for (int row = 0; row < farthest.rows; ++row) {
    auto* f = farthest.ptr<float>(row);
    for (int col = 0; col < farthest.cols; ++col) f[col] = f[col] > 0 ? f[col] : kNoSurface;
  }
  cv::erode(farthest, surface, window);
  for (int row = 0; row < surface.rows; ++row) {
    auto* s = surface.ptr<float>(row);
    for (int col = 0; col < surface.cols; ++col) {
      s[col] = pick(s[col] == kNoSurface, std::numeric_limits<float>::quiet_NaN(), s[col]);
    }
  }
}

// Follows the relief from a start (a plane or the envelope) on the half-resolution grid
// (the surface varies over several pixels, and this is a quarter of the work). Each pass:
// the soil is what is supported and lies no higher than height_mm above the current
// surface; the new surface is the Gaussian-weighted mean of its depths, or stays where
// there is too little soil nearby (under a hundredth of the kernel's weight).
void follow_relief(const cv::Mat& supported, double height_mm, double surface_px,
                   cv::Mat& surface) {
  thread_local cv::Mat soil;  // (depth, 1) of each soil pixel, (0, 0) elsewhere
  soil.create(supported.size(), CV_32FC2);
  const float below = static_cast<float>(height_mm);
  for (int pass = 0; pass < kLocalPasses; ++pass) {
    for (int row = 0; row < supported.rows; ++row) {
      const auto* d = supported.ptr<float>(row);
      const auto* s = surface.ptr<float>(row);
      auto* out = soil.ptr<float>(row);
      for (int col = 0; col < supported.cols; ++col) {
        // `&`, not `&&`: no branch, so that the loop vectorises. NaN: not soil.
        const float is_soil = static_cast<float>((d[col] > 0) & (s[col] - d[col] < below));
        out[2 * col] = is_soil * d[col];
        out[2 * col + 1] = is_soil;
      }
    }
    cv::GaussianBlur(soil, soil, {0, 0}, surface_px / 2);
    for (int row = 0; row < surface.rows; ++row) {
      auto* s = surface.ptr<float>(row);
      const auto* mean = soil.ptr<float>(row);
      for (int col = 0; col < surface.cols; ++col) {
        const float weight = mean[2 * col + 1];
        s[col] = pick(weight > 0.01f, mean[2 * col] / std::max(weight, 0.01f), s[col]);
      }
    }
  }
}

// Each pixel's height above the half-resolution surface, upsampled bilinearly (pixel
// centres aligned, edges clamped); NaN where the pixel has no depth.
void heights_above(const cv::Mat& half, const cv::Mat& depth, const cv::Mat& missing,
                   cv::Mat& height) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  thread_local std::vector<float> blended, surface;  // one row: half, padded; full
  blended.resize(static_cast<std::size_t>(half.cols) + 2);
  surface.resize(static_cast<std::size_t>(2 * half.cols));
  height.create(depth.size(), CV_32FC1);
  for (int row = 0; row < depth.rows; ++row) {
    const int other = std::clamp(row % 2 == 0 ? row / 2 - 1 : row / 2 + 1, 0, half.rows - 1);
    const auto* near_line = half.ptr<float>(row / 2);
    const auto* other_line = half.ptr<float>(other);
    float* const line = blended.data() + 1;
    for (int col = 0; col < half.cols; ++col) {
      line[col] = 0.75f * near_line[col] + 0.25f * other_line[col];
    }
    line[-1] = line[0];
    line[half.cols] = line[half.cols - 1];
    for (int col = 0; col < half.cols; ++col) {
      surface[2 * col] = 0.75f * line[col] + 0.25f * line[col - 1];
      surface[2 * col + 1] = 0.75f * line[col] + 0.25f * line[col + 1];
    }
    const auto* d = depth.ptr<float>(row);
    const auto* none = missing.ptr<std::uint8_t>(row);
    auto* out = height.ptr<float>(row);
    for (int col = 0; col < depth.cols; ++col) {
      out[col] = pick((none[col] == 0) & (d[col] > 0), surface[col] - d[col], kNaN);
    }
  }
}

// Each pixel's height above `plane`; NaN where the pixel has no depth, and everywhere
// without a plane.
void heights_above(const std::optional<Plane>& plane, const cv::Mat& depth, const cv::Mat& missing,
                   cv::Mat& height) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  height.create(depth.size(), CV_32FC1);
  if (!plane) {
    height.setTo(kNaN);
    return;
  }
  for (int row = 0; row < depth.rows; ++row) {
    const auto* d = depth.ptr<float>(row);
    const auto* none = missing.ptr<std::uint8_t>(row);
    auto* out = height.ptr<float>(row);
    const auto start = static_cast<float>(plane->at(0.0, row));
    const auto step = static_cast<float>(plane->a);
    for (int col = 0; col < depth.cols; ++col) {
      const float at = start + step * static_cast<float>(col);
      out[col] = pick((none[col] == 0) & (d[col] > 0), at - d[col], kNaN);
    }
  }
}

// The envelope's window on the half-resolution grid: odd, about envelope_px / 2 wide.
cv::Mat envelope_window(double envelope_px) {
  if (envelope_px <= 0) return {};
  const int side = 2 * static_cast<int>(std::lround(envelope_px / 4)) + 1;
  return cv::getStructuringElement(cv::MORPH_RECT, {side, side});
}

}  // namespace

SoilSurface::SoilSurface(double height_mm, double max_height_mm, double surface_px,
                         double envelope_px)
    : height_mm_(height_mm),
      max_height_mm_(std::max(height_mm, max_height_mm)),
      surface_px_(surface_px),
      envelope_window_(envelope_window(envelope_px)) {}

double SoilSurface::residue_height_mm(const cv::Mat& depth_mm) const {
  if (max_height_mm_ <= height_mm_) return height_mm_;
  const double noise_mm = depth_noise_mm(depth_mm, cv::Rect(0, 0, depth_mm.cols, depth_mm.rows),
                                         static_cast<float>(height_mm_ / kHeightPerNoise));
  return std::clamp(kHeightPerNoise * noise_mm, height_mm_, max_height_mm_);
}

double SoilSurface::heights(const cv::Mat& depth_mm, const cv::Mat& missing,
                            const cv::Mat& candidates, cv::Mat& height_mm) const {
  return heights(depth_mm, missing, candidates, height_mm, nullptr);
}

double SoilSurface::heights(const cv::Mat& depth_mm, const cv::Mat& missing,
                            const cv::Mat& candidates, cv::Mat& height_mm,
                            cv::Mat& plane_height_mm) const {
  return heights(depth_mm, missing, candidates, height_mm, &plane_height_mm);
}

double SoilSurface::heights(const cv::Mat& depth_mm, const cv::Mat& missing,
                            const cv::Mat& candidates, cv::Mat& height_mm,
                            cv::Mat* plane_height_mm) const {
  const double residue_mm = residue_height_mm(depth_mm);
  thread_local cv::Mat zeroed, depth, supported, surface;
  // A 3x3 median: a third of the ToF noise, and single dropouts (0 here) do not count;
  // where most neighbours have none, neither has the pixel.
  zeroed.create(depth_mm.size(), CV_32FC1);
  for (int row = 0; row < depth_mm.rows; ++row) {
    const auto* in = depth_mm.ptr<float>(row);
    const auto* none = missing.ptr<std::uint8_t>(row);
    auto* out = zeroed.ptr<float>(row);
    for (int col = 0; col < depth_mm.cols; ++col) out[col] = pick(none[col] == 0, in[col], 0.0f);
  }
  cv::medianBlur(zeroed, depth, 3);
  half_support(depth, missing, candidates, supported);

  const bool from_plane = envelope_window_.empty();
  std::optional<Plane> plane;
  if (from_plane) {
    plane = farthest_plane(depth, missing, candidates, kSampleStepPx);
  } else if (plane_height_mm != nullptr) {
    plane = farthest_plane(depth, missing, candidates, kBesideEnvelopeStepPx);
  }
  if (plane_height_mm != nullptr) heights_above(plane, depth, missing, *plane_height_mm);
  if (from_plane) {
    if (!plane) {
      height_mm.create(depth_mm.size(), CV_32FC1);
      height_mm.setTo(std::numeric_limits<float>::quiet_NaN());
      return residue_mm;
    }
    surface.create(supported.size(), CV_32FC1);
    for (int row = 0; row < surface.rows; ++row) {
      auto* s = surface.ptr<float>(row);
      for (int col = 0; col < surface.cols; ++col) {
        s[col] = static_cast<float>(plane->at(2 * col + 0.5, 2 * row + 0.5));
      }
    }
  } else {
    envelope(supported, envelope_window_, surface);
  }
  if (surface_px_ > 0) follow_relief(supported, residue_mm, surface_px_, surface);
  heights_above(surface, depth, missing, height_mm);
  return residue_mm;
}

ParamSpec height_mm_param() {
  return ParamSpec::number("height_mm", 3.0)
      .range(0.5, 100)
      .in_unit("mm")
      .describe("pixels more than this above the fitted soil surface are residue");
}

ParamSpec max_height_mm_param() {
  return ParamSpec::number("max_height_mm", 4.0)
      .range(0.5, 100)
      .in_unit("mm")
      .describe(
          "in a frame whose depth is noisier, height_mm rises to 1.7 standard deviations of "
          "the 3x3 median depth's noise, up to this (straw lying on straw must stay above "
          "it); at most height_mm: never");
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
