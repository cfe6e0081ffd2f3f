// estimation.ground_plane: the ground under the tool -- the soil surface around the tool's
// position, fitted as a smooth piece of ground and read there, with the ground's tilt.
//
//   soil_depth ──► enough soil? ──► soil points (X, Y, Z) on a sampling grid ──►
//   the ground's tilt: medians of the local slopes ──► the tool's level: the soil depths
//   with that tilt taken out, from their median near the tool point to the nearest mode
//   (mean shift) ──► a quadric surface fitted to the soil points within the outlier
//   threshold of it (weighted least squares with Tukey's biweight, re-selected until it
//   settles) ──► steps in its residuals (min_step_mm)? ── yes ──► the points on the tool's
//   side of them, fitted again ──► distance at tool_point,
//   tilt, spread = weighted RMS of the inlier residuals
//
// Why in this order. A step in the ground shows as two levels with the same tilt; a plane
// fitted freely can tilt to pass through both. The tilt taken from the medians of local
// slopes (a step is a slope only along its edge) and the level found by its mode near the
// tool keep the fit on the level the tool stands on. The quadric follows the curvature of
// ridges and furrows, so the fit can weigh soil from farther away (`neighbourhood_mm`) and
// average out clods and relief; cut at the steps (ground_steps.h), it can do so without
// averaging a step's two levels.
//
// The outlier threshold is `outlier_threshold_mm`, or kBandPerNoise times the soil depths'
// noise when that is more (depth_noise_mm), up to three times the threshold: a band
// narrower than the noise splits one surface's points at random, and the mean shift and
// the fit then settle wherever they start.
//
// `neighbourhood_mm` weights each point by a Gaussian of its distance from the tool point
// across the ground; 0 weighs all points alike. `tool_area_mm` is the scale of the soil
// that decides which level the tool stands on; 0 lets all the soil decide.
//
// Tilts are slope angles: tilt_x_deg = atan(dZ/dY) (the ground turned
// about the camera's x axis; positive when it is farther towards +y, the bottom of the
// image), tilt_y_deg = atan(dZ/dX) (about the y axis; positive when it is farther towards
// +x, the right).
//
//   "estimate": {"type": "estimation.ground_plane",
//                "params": {"tool_point": [0, 120], "neighbourhood_mm": 100, "min_step_mm": 2,
//                           "tool_area_mm": 10, "outlier_threshold_mm": 3}}
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "camera_geometry/lens_model.h"
#include "depth_noise/depth_noise.h"
#include "estimators.h"
#include "ground_steps.h"
#include "plausibility.h"
#include "soil_region.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/frame_calibration.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/registered_color.h"
#include "tilth/plugin.h"
#include "upper_median.h"

namespace tilth::estimation {
namespace {

// A bound only: re-fitting stops as soon as the depth at the tool point settles.
constexpr int kMaxRefits = 10;
// A bound only: the mean shift stops when the level moves less than kLevelSettledMm.
constexpr int kMaxLevelShifts = 30;
constexpr double kLevelSettledMm = 1e-2;
// Local slopes span this many grid steps: long enough that range noise moves them little,
// short enough that few of them cross a step's edge.
constexpr std::size_t kSlopeSpan = 3;
// Slopes from every kSlopeRowStep-th row of the grid: their medians need thousands, not all.
constexpr std::size_t kSlopeRowStep = 2;
// Points farther than 3 neighbourhoods from the tool point are left out of the fit.
constexpr double kNegligibleWeight = 1e-2;
const double kNegligibleExponent = -std::log(kNegligibleWeight);
// The quadric's coordinates are (X, Y) from the tool point in units of kQuadricScaleMm,
// so that its normal equations are well conditioned.
constexpr double kQuadricScaleMm = 100.0;
// The step search looks at every kStepSampleStep-th soil point: thousands, not all.
constexpr std::size_t kStepSampleStep = 4;
// At most this many steps are cut off, the highest first.
constexpr int kMaxSteps = 3;

struct GridPixel {
  int row;
  int col;
  float x;  // undistorted normalised coordinates of the pixel's ray
  float y;
};

struct SoilPoint {
  double x;  // camera frame, mm
  double y;
  double z;       // optical-centre depth, mm
  double weight;  // in the fit: nearness to the tool point at the neighbourhood's scale
  double vote;    // in choosing the tool's level: nearness at the tool area's scale
};

// A point of the sampling grid, in the camera frame (mm); z NaN where there is no soil.
struct GridPoint {
  float x;
  float y;
  float z;
};

// The ground's slopes in the camera frame: Z = Z0 + dz_dx X + dz_dy Y.
struct Tilt {
  double dz_dx;
  double dz_dy;

  double level(const SoilPoint& point) const { return point.z - dz_dx * point.x - dz_dy * point.y; }
};

// Z as a quadratic polynomial of (X, Y) about the tool point.
class Quadric {
 public:
  using Vector = Eigen::Matrix<double, 6, 1>;

  Quadric(cv::Vec2d origin_mm, double level, const Tilt& tilt) : origin_mm_(origin_mm) {
    coefficients_ << level + tilt.dz_dx * origin_mm[0] + tilt.dz_dy * origin_mm[1],
        tilt.dz_dx * kQuadricScaleMm, tilt.dz_dy * kQuadricScaleMm, 0, 0, 0;
  }

  double residual_mm(const SoilPoint& point) const {
    return point.z - fitted(terms(point.x, point.y));
  }

  double depth_at_origin() const { return coefficients_[0]; }
  double slope_x_at_origin() const { return coefficients_[1] / kQuadricScaleMm; }  // dZ/dX
  double slope_y_at_origin() const { return coefficients_[2] / kQuadricScaleMm; }  // dZ/dY

  // Weighted least squares on the points within `threshold_mm` of this surface, each also
  // weighed by Tukey's biweight of its residual (1 on the surface, 0 at the threshold), so
  // that the fringe of a neighbouring level does not pull the surface onto it; false (and
  // unchanged) when they do not determine a quadric.
  bool refit(const std::vector<SoilPoint>& points, double threshold_mm) {
    // The normal equations' entries are the weighted moments of u^i v^j (i + j <= 4): 15
    // sums instead of a 6x6 rank update per point; the right-hand side's, z u^i v^j.
    std::array<double, kMoments> moments{};
    std::array<double, 6> right{};
    const double per_threshold = 1.0 / threshold_mm;
    for (const SoilPoint& point : points) {
      const Terms t = terms(point.x, point.y);
      const double relative = (point.z - fitted(t)) * per_threshold;
      if (std::abs(relative) > 1) continue;
      const double biweight = (1 - relative * relative) * (1 - relative * relative);
      const double w = point.weight * biweight;
      const double u = t[1], v = t[2];
      const double wu = w * u, wv = w * v;
      const double wuu = wu * u, wuv = wu * v, wvv = wv * v;
      const double wuuu = wuu * u, wuuv = wuu * v, wuvv = wuv * v, wvvv = wvv * v;
      const std::array<double, kMoments> added = {w,        wu,       wv,       wuu,      wuv,
                                                  wvv,      wuuu,     wuuv,     wuvv,     wvvv,
                                                  wuuu * u, wuuu * v, wuuv * v, wuvv * v, wvvv * v};
      for (std::size_t i = 0; i < kMoments; ++i) moments[i] += added[i];
      const double z = point.z;
      const std::array<double, 6> weighted = {w * z, wu * z, wv * z, wuu * z, wuv * z, wvv * z};
      for (std::size_t i = 0; i < 6; ++i) right[i] += weighted[i];
    }
    Eigen::Matrix<double, 6, 6> normal;
    for (std::size_t i = 0; i < 6; ++i) {
      for (std::size_t j = 0; j < 6; ++j) {
        normal(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            moments[kMomentOf[i][j]];
      }
    }
    const Eigen::LDLT<Eigen::Matrix<double, 6, 6>> solver(normal);
    if (solver.info() != Eigen::Success ||
        solver.vectorD().minCoeff() <= 1e-12 * solver.vectorD().maxCoeff()) {
      return false;  // too few inliers, or all on a line
    }
    coefficients_ = solver.solve(Vector(right.data()));
    return true;
  }

 private:
  using Terms = std::array<double, 6>;  // 1, u, v, u^2, u v, v^2

  // The moments of u^i v^j by degree, then by i falling: 1; u, v; u^2, u v, v^2; ...
  static constexpr std::size_t kMoments = 15;
  // The moment of the product of terms i and j.
  static constexpr std::size_t kMomentOf[6][6] = {{0, 1, 2, 3, 4, 5},    {1, 3, 4, 6, 7, 8},
                                                  {2, 4, 5, 7, 8, 9},    {3, 6, 7, 10, 11, 12},
                                                  {4, 7, 8, 11, 12, 13}, {5, 8, 9, 12, 13, 14}};

  Terms terms(double x_mm, double y_mm) const {
    constexpr double kPerScale = 1.0 / kQuadricScaleMm;
    const double u = (x_mm - origin_mm_[0]) * kPerScale;
    const double v = (y_mm - origin_mm_[1]) * kPerScale;
    return {1.0, u, v, u * u, u * v, v * v};
  }

  double fitted(const Terms& t) const {
    double z = 0.0;
    for (std::size_t i = 0; i < t.size(); ++i)
      z += coefficients_[static_cast<Eigen::Index>(i)] * t[i];
    return z;
  }

  cv::Vec2d origin_mm_;
  Vector coefficients_;
};

// The medians of the slopes of the triangles (p, p + kSlopeSpan to the right, p +
// kSlopeSpan down) of soil grid points; nullopt without enough of them.
std::optional<Tilt> ground_tilt(const std::vector<GridPoint>& grid, std::size_t columns) {
  thread_local std::vector<double> dz_dx;
  thread_local std::vector<double> dz_dy;
  dz_dx.clear();
  dz_dy.clear();
  const std::size_t rows = grid.size() / columns;
  for (std::size_t row = 0; row + kSlopeSpan < rows; row += kSlopeRowStep) {
    for (std::size_t col = 0; col + kSlopeSpan < columns; ++col) {
      const GridPoint& p = grid[row * columns + col];
      const GridPoint& right = grid[row * columns + col + kSlopeSpan];
      const GridPoint& below = grid[(row + kSlopeSpan) * columns + col];
      if (!std::isfinite(p.z) || !std::isfinite(right.z) || !std::isfinite(below.z)) continue;
      // dZ = dz_dx dX + dz_dy dY along both sides, by Cramer's rule.
      const double x1 = right.x - p.x, y1 = right.y - p.y, z1 = right.z - p.z;
      const double x2 = below.x - p.x, y2 = below.y - p.y, z2 = below.z - p.z;
      const double determinant = x1 * y2 - y1 * x2;  // about the triangle's area: never near 0
      dz_dx.push_back((z1 * y2 - y1 * z2) / determinant);
      dz_dy.push_back((x1 * z2 - z1 * x2) / determinant);
    }
  }
  if (dz_dx.size() < 3) return std::nullopt;
  return Tilt{upper_median(dz_dx), upper_median(dz_dy)};
}

// The level (depth with the tilt taken out) the tool stands on: from the median of the
// levels weighed by their votes, the mean shift (window +-threshold, fit weights) to the
// nearest mode.
double tool_level(const std::vector<SoilPoint>& points, const Tilt& tilt, double threshold_mm) {
  thread_local std::vector<double> levels;
  thread_local std::vector<std::pair<double, double>> voted;  // level, vote
  levels.clear();
  voted.clear();
  double votes = 0.0;
  for (const SoilPoint& point : points) {
    levels.push_back(tilt.level(point));
    if (point.vote < kNegligibleWeight) continue;
    voted.emplace_back(levels.back(), point.vote);
    votes += point.vote;
  }
  std::sort(voted.begin(), voted.end());
  double level = voted.back().first;
  double below = 0.0;
  for (const auto& [candidate, vote] : voted) {
    below += vote;
    if (below >= votes / 2) {
      level = candidate;
      break;
    }
  }
  for (int shift = 0; shift < kMaxLevelShifts; ++shift) {
    double weight = 0.0;
    double sum = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      // No branch: the points near the window's edges would mispredict one.
      const double in_window = std::abs(levels[i] - level) <= threshold_mm ? 1.0 : 0.0;
      weight += in_window * points[i].weight;
      sum += in_window * points[i].weight * levels[i];
    }
    if (weight <= 0.0) break;
    const double moved = sum / weight - level;
    level += moved;
    if (std::abs(moved) < kLevelSettledMm) break;
  }
  return level;
}

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

cv::Vec2d parse_tool_point(const nlohmann::json& value) {
  if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number()) {
    throw Error("parameter 'tool_point': expected [x_mm, y_mm] in the ToF camera frame, got " +
                value.dump());
  }
  return {value[0].get<double>(), value[1].get<double>()};
}

std::string size_text(cv::Size size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Every stride-th pixel of the region, with its ray, computed once. `where` names the
// calibration's distortion in an error.
std::vector<GridPixel> sampling_grid(const DepthCameraCalibration& camera, const cv::Rect& roi,
                                     int stride, const std::string& where) {
  std::vector<cv::Point2d> pixels;
  for (int row = roi.y; row < roi.y + roi.height; row += stride) {
    for (int col = roi.x; col < roi.x + roi.width; col += stride) pixels.emplace_back(col, row);
  }
  const std::vector<cv::Point2d> rays = lens::undistort(camera, pixels, where);
  std::vector<GridPixel> grid;
  grid.reserve(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    grid.push_back({static_cast<int>(pixels[i].y), static_cast<int>(pixels[i].x),
                    static_cast<float>(rays[i].x), static_cast<float>(rays[i].y)});
  }
  return grid;
}

// What fitting a frame's ground needs from its calibration.
struct Sampling {
  DepthCameraCalibration camera;
  cv::Size image_size;
  cv::Rect roi;
  std::vector<GridPixel> grid;  // row by row
  std::size_t grid_columns;
};

class GroundPlaneEstimator final : public Transform {
 public:
  enum Port { kSoilDepth = 0, kColor = 1 };

  // The chain's 3 mm band against the simulator's soil noise, 1.3-2.1 mm: about 1.5 sigma.
  // At most three times the threshold: depths that are no surface at all (a ToF image of
  // noise) must not widen the band until they fit.
  static constexpr double kBandPerNoise = 1.5;
  static constexpr double kMaxBandPerThreshold = 3.0;

  explicit GroundPlaneEstimator(const StageContext& context)
      : region_(context.params.json("roi"), RegionOfInterest::Whole::kMiddleHalf),
        tool_point_mm_(parse_tool_point(context.params.json("tool_point"))),
        requirement_(soil_requirement(context.params)),
        threshold_mm_(context.params.number("outlier_threshold_mm")),
        neighbourhood_mm_(context.params.number("neighbourhood_mm")),
        tool_area_mm_(context.params.number("tool_area_mm")),
        min_inlier_fraction_(context.params.number("min_inlier_fraction")),
        min_surrounding_fraction_(context.params.number("min_surrounding_fraction")),
        min_step_mm_(context.params.number("min_step_mm")),
        gates_(context.params),
        calibration_(
            context.params, context.log,
            [this, log = context.log, stride = static_cast<int>(context.params.integer("stride"))](
                const RigCalibration& rig) {
              const cv::Size size(rig.depth.width, rig.depth.height);
              if (region_.clipped_on(size)) log.warning(region_.clipping_note(size));
              const cv::Rect roi = region_.on(size);
              return Sampling{
                  rig.depth, size, roi,
                  sampling_grid(rig.depth, roi, stride, rig.origin + ":/depth_camera/distortion"),
                  static_cast<std::size_t>((roi.width + stride - 1) / stride)};
            }) {}

  void process(Frame& frame) override {
    const auto& soil = frame.input<DepthImage>(kSoilDepth);
    const auto used = calibration_.for_frame(soil.rig);
    const Sampling& sampling = used->derived;
    if (soil.mm.type() != CV_32FC1 || soil.mm.size() != sampling.image_size) {
      throw Error("input 'soil_depth': expected a CV_32FC1 " + size_text(sampling.image_size) +
                  " image (the calibration's depth camera), got type " +
                  std::to_string(soil.mm.type()) + ", " + size_text(soil.mm.size()));
    }
    const cv::Rect& roi = sampling.roi;
    GroundDistance out;
    out.soil_pixels = count_finite(soil.mm, roi);
    out.soil_fraction = static_cast<double>(out.soil_pixels) / roi.area();
    if (const Packet& color = frame.input(kColor); !color.empty()) {
      if (auto unusable = gates_.unusable_color(color.get<RegisteredColor>(), roi)) {
        out.invalidate(InvalidCause::kImageUnusable, std::move(*unusable));
        frame.emit(0, std::move(out));
        return;
      }
    }
    if (auto shortfall = requirement_.shortfall(out.soil_pixels, roi.area()); !shortfall.empty()) {
      out.invalidate(InvalidCause::kTooLittleSoil, std::move(shortfall));
    } else {
      measure(sampling, soil.mm, out);
      gates_.check(out);
    }
    frame.emit(0, std::move(out));
  }

 private:
  void measure(const Sampling& sampling, const cv::Mat& soil_mm, GroundDistance& out) const {
    const DepthCameraCalibration& camera = sampling.camera;
    const double noise_mm =
        depth_noise_mm(soil_mm, sampling.roi, static_cast<float>(threshold_mm_ / kBandPerNoise));
    const double band_mm = std::min(kBandPerNoise * noise_mm, kMaxBandPerThreshold * threshold_mm_);
    thread_local std::vector<GridPoint> grid;  // every grid pixel
    thread_local std::vector<SoilPoint> points;
    // The soil points first, without a branch (soil and residue alternate unpredictably),
    // then their weights, leaving out those too far to count.
    grid.resize(sampling.grid.size());
    points.resize(sampling.grid.size());
    std::size_t soil = 0;
    for (std::size_t i = 0; i < sampling.grid.size(); ++i) {
      const GridPixel& pixel = sampling.grid[i];
      const float depth = soil_mm.at<float>(pixel.row, pixel.col);
      const double z = depth + camera.z_offset_mm;  // NaN where no soil
      const double x = pixel.x * z;
      const double y = pixel.y * z;
      grid[i] = {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
      points[soil] = {x, y, z, 0.0, 0.0};
      soil += std::isfinite(depth) ? 1 : 0;
    }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < soil; ++i) {
      SoilPoint point = points[i];
      point.weight = nearness(point.x, point.y, neighbourhood_mm_);
      if (point.weight < kNegligibleWeight) continue;
      point.vote = nearness(point.x, point.y, tool_area_mm_);
      points[kept++] = point;
    }
    points.resize(kept);
    vote_near_the_tool(points);
    const std::optional<Tilt> tilt = ground_tilt(grid, sampling.grid_columns);
    if (!tilt || points.size() < 6) {
      out.invalidate(InvalidCause::kTooLittleSoil,
                     "too few soil points on the sampling grid to fit the ground (lower "
                     "'stride')");
      return;
    }
    std::optional<Quadric> surface = fitted_surface(points, *tilt, band_mm);
    if (surface && min_step_mm_ > 0 && cut_at_steps(*surface, points)) {
      if (points.size() < 6) {
        out.invalidate(InvalidCause::kTooLittleSoil,
                       "too few soil points on the tool's side of a step in the ground");
        return;
      }
      vote_near_the_tool(points);
      surface = fitted_surface(points, *tilt, band_mm);
    }
    if (!surface) {
      out.invalidate(InvalidCause::kNotOneSurface,
                     "no surface fits the soil points (too few inliers, or all on a line)");
      return;
    }

    double weight = 0.0;
    double inlier_weight = 0.0;
    double squares = 0.0;
    double votes = 0.0;
    double inlier_votes = 0.0;
    SoilBeyond beyond = gates_.soil_beyond(noise_mm);
    for (const SoilPoint& point : points) {
      votes += point.vote;
      weight += point.weight;
      const double residual_mm = surface->residual_mm(point);
      beyond.add(point.x - tool_point_mm_[0], point.y - tool_point_mm_[1], residual_mm,
                 point.weight);
      if (std::abs(residual_mm) > band_mm) continue;
      inlier_votes += point.vote;
      inlier_weight += point.weight;
      squares += point.weight * residual_mm * residual_mm;
    }
    const double inlier_fraction = inlier_votes / votes;
    if (inlier_fraction < min_inlier_fraction_) {
      out.invalidate(InvalidCause::kNotOneSurface,
                     "no surface fits the soil: " + one_decimal(100.0 * inlier_fraction) +
                         " % of the soil points (by weight) lie within " + one_decimal(band_mm) +
                         " mm of the tool's < " + one_decimal(100.0 * min_inlier_fraction_) + " %");
      return;
    }
    // A tool is wider than a crack or a hole and rests on the ground around it: a level
    // voted from the soil in one (heavy cover leaves little else in view near the tool)
    // holds a minority of the soil around the tool.
    if (const double surrounding = inlier_weight / weight;
        surrounding < min_surrounding_fraction_) {
      out.invalidate(InvalidCause::kNotOneSurface,
                     "the tool's surface holds too little of the soil around it: " +
                         one_decimal(100.0 * surrounding) +
                         " % of the soil points (by nearness) lie within " + one_decimal(band_mm) +
                         " mm of it < " + one_decimal(100.0 * min_surrounding_fraction_) +
                         " % (the tool point over a crack or a hole?)");
      return;
    }
    const double depth_at_tool = surface->depth_at_origin();
    if (!std::isfinite(depth_at_tool) || depth_at_tool <= 0) {
      out.invalidate(InvalidCause::kOutOfRange,
                     "the fitted surface does not lie in front of the camera at the tool point");
      return;
    }
    out.spread_mm = std::sqrt(squares / inlier_weight);
    out.distance_mm = depth_at_tool - camera.z_offset_mm;
    out.tilt_x_deg = degrees(std::atan(surface->slope_y_at_origin()));
    out.tilt_y_deg = degrees(std::atan(surface->slope_x_at_origin()));
    out.valid = true;
    out.confidence = confidence(out.soil_fraction, out.spread_mm) * inlier_fraction;

    gates_.check_soil_beyond(out, beyond);
  }

  // The quadric on the tool's level, re-fitted until it settles; nullopt when the points
  // do not determine one.
  std::optional<Quadric> fitted_surface(const std::vector<SoilPoint>& points, const Tilt& tilt,
                                        double band_mm) const {
    Quadric surface(tool_point_mm_, tool_level(points, tilt, band_mm), tilt);
    for (int refit = 0; refit < kMaxRefits; ++refit) {
      const double before = surface.depth_at_origin();
      if (!surface.refit(points, band_mm)) return std::nullopt;
      if (std::abs(surface.depth_at_origin() - before) < kLevelSettledMm) break;
    }
    return surface;
  }

  // Leaves only the points on the tool point's side of the steps in the ground that the
  // residuals of `surface` show (ground_steps.h); false when there are none.
  bool cut_at_steps(const Quadric& surface, std::vector<SoilPoint>& points) const {
    thread_local std::vector<LevelPoint> sample;
    sample.clear();
    for (std::size_t i = 0; i < points.size(); i += kStepSampleStep) {
      sample.push_back({points[i].x - tool_point_mm_[0], points[i].y - tool_point_mm_[1],
                        surface.residual_mm(points[i])});
    }
    bool cut = false;
    for (int found = 0; found < kMaxSteps; ++found) {
      const std::optional<GroundStep> step = highest_step(sample, min_step_mm_);
      if (!step) break;
      cut = true;
      const auto beyond = [&](double x, double y) { return step->cuts_off(x, y); };
      std::erase_if(sample, [&](const LevelPoint& p) { return beyond(p.x_mm, p.y_mm); });
      std::erase_if(points, [&](const SoilPoint& p) {
        return beyond(p.x - tool_point_mm_[0], p.y - tool_point_mm_[1]);
      });
    }
    return cut;
  }

  // No soil within the tool area (residue covers it): the soil nearest the tool, by the
  // fit's weights, decides the level.
  static void vote_near_the_tool(std::vector<SoilPoint>& points) {
    if (std::none_of(points.begin(), points.end(),
                     [](const SoilPoint& point) { return point.vote >= kNegligibleWeight; })) {
      for (SoilPoint& point : points) point.vote = point.weight;
    }
  }

  // A Gaussian (sigma `scale_mm`) of a point's distance across the ground from the tool
  // point; 1 for every point when the scale is 0.
  // Below kNegligibleWeight it is 0, without computing the exponential.
  double nearness(double x_mm, double y_mm, double scale_mm) const {
    if (scale_mm <= 0) return 1.0;
    const double dx = x_mm - tool_point_mm_[0];
    const double dy = y_mm - tool_point_mm_[1];
    const double exponent = (dx * dx + dy * dy) / (2 * scale_mm * scale_mm);
    return exponent > kNegligibleExponent ? 0.0 : std::exp(static_cast<float>(-exponent));
  }

  const RegionOfInterest region_;
  const cv::Vec2d tool_point_mm_;
  const SoilRequirement requirement_;
  const double threshold_mm_;
  const double neighbourhood_mm_;
  const double tool_area_mm_;
  const double min_inlier_fraction_;
  const double min_surrounding_fraction_;
  const double min_step_mm_;
  const PlausibilityGates gates_;
  FrameCalibration<Sampling> calibration_;
};

}  // namespace

StageDescriptor describe_ground_plane() {
  StageDescriptor d;
  d.type = "estimation.ground_plane";
  d.summary = "ground distance at the tool and ground tilt from a robust fit of the soil surface";
  d.inputs = {PortSpec::of<DepthImage>("soil_depth", "depth of the soil pixels, NaN elsewhere"),
              PlausibilityGates::color_port()};
  d.outputs = {PortSpec::of<GroundDistance>(
      "distance", "distance at the tool point, tilt, validity, spread (inlier RMS), confidence")};
  d.params = {
      frame_calibration_param(),
      roi_param(RegionOfInterest::Whole::kMiddleHalf),
      ParamSpec::json("tool_point", nlohmann::json::array({0.0, 0.0}))
          .in_unit("mm")
          .describe("[x, y] in the ToF camera frame where the distance is read; [0, 0] = axis"),
      min_soil_fraction_param(),
      min_soil_pixels_param(),
      ParamSpec::number("neighbourhood_mm", 0.0)
          .range(0, 10000)
          .in_unit("mm")
          .describe("soil points weigh by a Gaussian (this sigma) of their distance from the "
                    "tool point; 0 = all alike"),
      ParamSpec::number("tool_area_mm", 0.0)
          .range(0, 10000)
          .in_unit("mm")
          .describe("the soil within about this distance of the tool point picks the level "
                    "it stands on (steps); 0 = all the soil"),
      ParamSpec::number("outlier_threshold_mm", 10.0)
          .range(0.1, 1000)
          .in_unit("mm")
          .describe("soil points farther than this from the surface (along Z) are outliers, "
                    "and levels farther apart are told apart; on noisier soil 1.5 times its "
                    "depth noise, up to three times this"),
      ParamSpec::number("min_inlier_fraction", 0.5)
          .range(0, 1)
          .describe("below this fraction of the soil points (weighed by their votes) on the "
                    "tool's surface the measurement is invalid"),
      ParamSpec::number("min_surrounding_fraction", 0.5)
          .range(0, 1)
          .describe("below this fraction of the soil points around the tool (weighed by "
                    "nearness, neighbourhood_mm) on the tool's surface the measurement is "
                    "invalid: the level came from a crack or a hole under the tool point"),
      ParamSpec::number("min_step_mm", 0.0)
          .range(0, 16)
          .in_unit("mm")
          .describe("the level jumping by this much along a straight line across the ground "
                    "is a step: the fit keeps to the tool's side of it; 0 = no search"),
      ParamSpec::integer("stride", 4)
          .range(1, 64)
          .in_unit("px")
          .describe("fit every stride-th pixel in each direction of the roi"),
  };
  const auto gates = PlausibilityGates::params();
  d.params.insert(d.params.end(), gates.begin(), gates.end());
  d.concurrency = Concurrency::kParallel;
  d.create = factory<GroundPlaneEstimator>();
  return d;
}

TILTH_STAGE(describe_ground_plane());

}  // namespace tilth::estimation
