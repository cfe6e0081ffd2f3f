// estimation.ground_plane: the ground under the tool -- a plane fitted to the soil points
// around the tool's position, read there, with the ground's tilt.
//
//   soil_depth ──► enough soil? ──► sampled rays (x', y') with depth Z, weighted by their
//   nearness to the tool point ──► up to max_surfaces pieces of ground, each RANSAC
//   (3-point planes, fixed seed, weighted) then least squares on its inliers, re-selected
//   until stable, on what the earlier pieces left ──► the piece the tool stands on ──►
//   distance at tool_point, tilt, spread = weighted RMS of the inlier residuals
//
// The plane is written a X + b Y + c Z = 1 in the ToF camera frame (origin at the optical
// centre), so along the ray of undistorted normalised coordinates (x', y') it lies at
// Z = 1 / (a x' + b y' + c): 1/Z is linear in (x', y'), which come from the calibration
// and carry no noise. Residuals are along Z, in mm.
//
// `neighbourhood_mm` weights each point by a Gaussian of its distance from the tool point
// across the ground, so the ground around the tool decides and a ridge or furrow
// elsewhere in the region does not tilt the fit; 0 weighs all points alike. Where the
// ground steps, `max_surfaces` > 1 fits the pieces in turn, and the points within about
// `tool_area_mm` of the tool point pick the one it stands on (the piece whose inliers
// hold the most of them, by a Gaussian of that scale).
//
// Tilts are slope angles: tilt_x_deg = atan(dZ/dY) (the ground turned
// about the camera's x axis; positive when it is farther towards +y, the bottom of the
// image), tilt_y_deg = atan(dZ/dX) (about the y axis; positive when it is farther towards
// +x, the right).
//
//   "estimate": {"type": "estimation.ground_plane",
//                "params": {"tool_point": [0, 120], "neighbourhood_mm": 40,
//                           "max_surfaces": 3, "tool_area_mm": 10}}
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>

#include "estimators.h"
#include "plausibility.h"
#include "soil_region.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/frame_calibration.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/registered_color.h"
#include "tilth/plugin.h"

namespace tilth::estimation {
namespace {

// A bound only: re-fitting stops as soon as the inlier set no longer changes.
constexpr int kMaxRefits = 10;
constexpr std::size_t kScoreStep = 4;
// Points farther than 3.7 neighbourhoods from the tool point are left out of the fit.
constexpr double kNegligibleWeight = 1e-3;
const double kNegligibleExponent = -std::log(kNegligibleWeight);
// Any fixed value: the same frame always gives the same surface.
constexpr std::uint32_t kRansacSeed = 20240611;

struct GridPixel {
  int row;
  int col;
  float x;  // undistorted normalised coordinates of the pixel's ray
  float y;
};

struct SoilPoint {
  double x;
  double y;
  double z;       // optical-centre depth, mm
  double weight;  // in the fit: nearness to the tool point at the neighbourhood's scale
  double vote;    // in choosing the tool's surface: nearness at the tool area's scale
};

// 1/Z as a function of (x', y'): the plane c + a x' + b y'.
class Surface {
 public:
  explicit Surface(const Eigen::Vector3d& cab) : cab_(cab) {}

  // The plane through three soil points, unless they are (nearly) collinear.
  static std::optional<Surface> through(const SoilPoint& p, const SoilPoint& q,
                                        const SoilPoint& r) {
    Eigen::Matrix3d rays;
    rays << 1, p.x, p.y, 1, q.x, q.y, 1, r.x, r.y;
    // Normalised coordinates span about 1, so this is twice the triangle's area in them.
    if (std::abs(rays.determinant()) < 1e-9) return std::nullopt;
    return Surface(rays.partialPivLu().solve(Eigen::Vector3d(1 / p.z, 1 / q.z, 1 / r.z)));
  }

  bool inlier(const SoilPoint& point, double threshold_mm) const {
    const double m = inverse_depth(point.x, point.y);
    return m > 0 && std::abs(point.z * m - 1) <= threshold_mm * m;  // |Z - 1/m| <= threshold
  }

  double residual_mm(const SoilPoint& point) const {
    return point.z - 1 / inverse_depth(point.x, point.y);
  }

  // Z of the plane at camera-frame (X, Y) (c Z + a X + b Y = 1); not finite, or not
  // positive, when the plane never gets there.
  double depth_at(double x_mm, double y_mm) const {
    return (1 - cab_[1] * x_mm - cab_[2] * y_mm) / cab_[0];
  }

  double slope_x() const { return -cab_[1] / cab_[0]; }  // dZ/dX
  double slope_y() const { return -cab_[2] / cab_[0]; }  // dZ/dY

 private:
  double inverse_depth(double x, double y) const { return cab_[0] + cab_[1] * x + cab_[2] * y; }

  Eigen::Vector3d cab_;
};

// Weighted least squares of the residuals along Z: Z - 1/m ~= Z^2 m - Z near the plane
// (m ~= 1/Z), which is linear in (c, a, b).
std::optional<Surface> fit(const std::vector<SoilPoint>& points, const std::vector<bool>& inliers) {
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d right = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!inliers[i]) continue;
    const SoilPoint& p = points[i];
    const Eigen::Vector3d row = p.z * p.z * Eigen::Vector3d(1, p.x, p.y);
    normal += p.weight * row * row.transpose();
    right += p.weight * p.z * row;
  }
  const Eigen::LDLT<Eigen::Matrix3d> solver(normal);
  if (solver.info() != Eigen::Success ||
      solver.vectorD().minCoeff() <= 1e-12 * solver.vectorD().maxCoeff()) {
    return std::nullopt;  // fewer than three inliers, or all on a line
  }
  return Surface(solver.solve(right));
}

// Marks the inliers of `surface`; returns their weight and whether any flag changed.
std::pair<double, bool> mark_inliers(const std::vector<SoilPoint>& points, const Surface& surface,
                                     double threshold_mm, std::vector<bool>& inliers) {
  double weight = 0.0;
  bool changed = false;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const bool inlier = surface.inlier(points[i], threshold_mm);
    changed = changed || inlier != inliers[i];
    inliers[i] = inlier;
    weight += inlier ? points[i].weight : 0.0;
  }
  return {weight, changed};
}

// Least squares on the inliers of `plane`, re-selected and re-fitted until they no longer
// change. Leaves the final inliers marked.
std::optional<Surface> refine(const std::vector<SoilPoint>& points, Surface plane,
                              double threshold_mm, std::vector<bool>& inliers) {
  inliers.assign(points.size(), false);
  bool changed = mark_inliers(points, plane, threshold_mm, inliers).second;
  for (int refit = 0; refit < kMaxRefits && changed; ++refit) {
    const std::optional<Surface> better = fit(points, inliers);
    if (!better) return std::nullopt;
    plane = *better;
    changed = mark_inliers(points, plane, threshold_mm, inliers).second;
  }
  return plane;
}

// Planes through three points drawn in proportion to their weight, scored by the weight of
// their inliers among every kScoreStep-th point (a sample as good as all of them for
// ranking the hypotheses: the best is refined on all).
std::optional<Surface> ransac(const std::vector<SoilPoint>& points, int hypotheses,
                              double threshold_mm) {
  thread_local std::vector<double> cumulative;
  cumulative.resize(points.size());
  double total = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) cumulative[i] = total += points[i].weight;
  std::mt19937 random(kRansacSeed);
  std::uniform_real_distribution<double> pick(0.0, total);
  const auto draw = [&]() -> const SoilPoint& {
    const auto at = std::upper_bound(cumulative.begin(), cumulative.end(), pick(random));
    return points[std::min<std::size_t>(at - cumulative.begin(), points.size() - 1)];
  };
  std::optional<Surface> best;
  double best_weight = 0.0;
  for (int h = 0; h < hypotheses; ++h) {
    const SoilPoint& p = draw();
    const SoilPoint& q = draw();
    const SoilPoint& r = draw();
    const auto plane = Surface::through(p, q, r);
    if (!plane) continue;
    double weight = 0.0;
    for (std::size_t i = 0; i < points.size(); i += kScoreStep) {
      if (plane->inlier(points[i], threshold_mm)) weight += points[i].weight;
    }
    if (weight > best_weight) {
      best = plane;
      best_weight = weight;
    }
  }
  return best;
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

// Every stride-th pixel of the region, with its ray, computed once.
std::vector<GridPixel> sampling_grid(const DepthCameraCalibration& camera, const cv::Rect& roi,
                                     int stride) {
  std::vector<cv::Point2f> pixels;
  for (int row = roi.y; row < roi.y + roi.height; row += stride) {
    for (int col = roi.x; col < roi.x + roi.width; col += stride) {
      pixels.emplace_back(static_cast<float>(col), static_cast<float>(row));
    }
  }
  std::vector<cv::Point2f> rays;
  cv::undistortPoints(pixels, rays, camera.camera_matrix(), camera.distortion);
  std::vector<GridPixel> grid;
  grid.reserve(pixels.size());
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    grid.push_back(
        {static_cast<int>(pixels[i].y), static_cast<int>(pixels[i].x), rays[i].x, rays[i].y});
  }
  return grid;
}

// What fitting a frame's plane needs from its calibration.
struct Sampling {
  DepthCameraCalibration camera;
  cv::Size image_size;
  cv::Rect roi;
  std::vector<GridPixel> grid;
};

class GroundPlaneEstimator final : public Transform {
 public:
  enum Port { kSoilDepth = 0, kColor = 1 };

  explicit GroundPlaneEstimator(const StageContext& context)
      : region_(context.params.json("roi"), RegionOfInterest::Whole::kMiddleHalf),
        tool_point_mm_(parse_tool_point(context.params.json("tool_point"))),
        requirement_(soil_requirement(context.params)),
        threshold_mm_(context.params.number("outlier_threshold_mm")),
        neighbourhood_mm_(context.params.number("neighbourhood_mm")),
        tool_area_mm_(context.params.number("tool_area_mm")),
        max_surfaces_(static_cast<int>(context.params.integer("max_surfaces"))),
        hypotheses_(static_cast<int>(context.params.integer("iterations"))),
        min_inlier_fraction_(context.params.number("min_inlier_fraction")),
        gates_(context.params),
        calibration_(
            context.params, context.log,
            [this, log = context.log, stride = static_cast<int>(context.params.integer("stride"))](
                const RigCalibration& rig) {
              const cv::Size size(rig.depth.width, rig.depth.height);
              if (region_.clipped_on(size)) log.warning(region_.clipping_note(size));
              const cv::Rect roi = region_.on(size);
              return Sampling{rig.depth, size, roi, sampling_grid(rig.depth, roi, stride)};
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
    thread_local std::vector<SoilPoint> points;
    thread_local std::vector<bool> inliers;
    points.clear();
    for (const GridPixel& pixel : sampling.grid) {
      const float depth = soil_mm.at<float>(pixel.row, pixel.col);
      if (!std::isfinite(depth)) continue;
      const double z = depth + camera.z_offset_mm;
      const double x = pixel.x * z;
      const double y = pixel.y * z;
      const double weight = nearness(x, y, neighbourhood_mm_);
      if (weight < kNegligibleWeight) continue;
      points.push_back({pixel.x, pixel.y, z, weight, nearness(x, y, tool_area_mm_)});
    }
    if (points.size() < 3) {
      out.invalidate(InvalidCause::kTooLittleSoil,
                     "too few soil points on the sampling grid: " + std::to_string(points.size()) +
                         " < 3 (lower 'stride')");
      return;
    }

    const std::optional<Surface> tool_surface = surface_under_tool(points, inliers);
    if (!tool_surface) {
      out.invalidate(InvalidCause::kNotOneSurface,
                     "no surface fits the soil points (too few inliers, or all on a line)");
      return;
    }
    const Surface& surface = *tool_surface;
    const double inlier_weight = mark_inliers(points, surface, threshold_mm_, inliers).first;
    double votes = 0.0;
    double inlier_votes = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      votes += points[i].vote;
      inlier_votes += inliers[i] ? points[i].vote : 0.0;
    }
    const double inlier_fraction = inlier_votes / votes;
    if (inlier_fraction < min_inlier_fraction_) {
      out.invalidate(InvalidCause::kNotOneSurface,
                     "no surface fits the soil: " + one_decimal(100.0 * inlier_fraction) +
                         " % of the soil points (by weight) lie within " +
                         one_decimal(threshold_mm_) + " mm of the best one < " +
                         one_decimal(100.0 * min_inlier_fraction_) + " %");
      return;
    }
    const double depth_at_tool = surface.depth_at(tool_point_mm_[0], tool_point_mm_[1]);
    if (!std::isfinite(depth_at_tool) || depth_at_tool <= 0) {
      out.invalidate(InvalidCause::kOutOfRange,
                     "the fitted surface does not lie in front of the camera at the tool point");
      return;
    }

    double squares = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (!inliers[i]) continue;
      const double residual_mm = surface.residual_mm(points[i]);
      squares += points[i].weight * residual_mm * residual_mm;
    }
    out.spread_mm = std::sqrt(squares / inlier_weight);
    out.distance_mm = depth_at_tool - camera.z_offset_mm;
    out.tilt_x_deg = degrees(std::atan(surface.slope_y()));
    out.tilt_y_deg = degrees(std::atan(surface.slope_x()));
    out.valid = true;
    out.confidence = confidence(out.soil_fraction, out.spread_mm) * inlier_fraction;
  }

  // A Gaussian (sigma `scale_mm`) of a point's distance across the ground from the tool
  // point; 1 for every point when the scale is 0.
  // Below kNegligibleWeight it is 0, without computing the exponential.
  double nearness(double x_mm, double y_mm, double scale_mm) const {
    if (scale_mm <= 0) return 1.0;
    const double dx = x_mm - tool_point_mm_[0];
    const double dy = y_mm - tool_point_mm_[1];
    const double exponent = (dx * dx + dy * dy) / (2 * scale_mm * scale_mm);
    return exponent > kNegligibleExponent ? 0.0 : std::exp(-exponent);
  }

  // Up to max_surfaces surfaces, each fitted (RANSAC, then least squares) to the soil
  // points the earlier ones left over; the tool's is the one whose inliers hold the most
  // of the points around the tool point (votes). One surface: the best fit of them all.
  std::optional<Surface> surface_under_tool(const std::vector<SoilPoint>& points,
                                            std::vector<bool>& inliers) const {
    thread_local std::vector<SoilPoint> left;
    left = points;
    std::optional<Surface> chosen;
    double chosen_votes = -1.0;
    for (int found = 0; found < max_surfaces_ && left.size() >= 3; ++found) {
      const std::optional<Surface> guess = ransac(left, hypotheses_, threshold_mm_);
      const std::optional<Surface> fitted =
          guess ? refine(left, *guess, threshold_mm_, inliers) : std::nullopt;
      if (!fitted) break;
      double votes = 0.0;
      std::size_t kept = 0;
      for (std::size_t i = 0; i < left.size(); ++i) {
        if (inliers[i]) {
          votes += left[i].vote;
        } else {
          left[kept++] = left[i];
        }
      }
      left.resize(kept);
      if (votes > chosen_votes) {
        chosen = fitted;
        chosen_votes = votes;
      }
    }
    return chosen;
  }

  const RegionOfInterest region_;
  const cv::Vec2d tool_point_mm_;
  const SoilRequirement requirement_;
  const double threshold_mm_;
  const double neighbourhood_mm_;
  const double tool_area_mm_;
  const int max_surfaces_;
  const int hypotheses_;
  const double min_inlier_fraction_;
  const PlausibilityGates gates_;
  FrameCalibration<Sampling> calibration_;
};

}  // namespace

StageDescriptor describe_ground_plane() {
  StageDescriptor d;
  d.type = "estimation.ground_plane";
  d.summary = "ground distance at the tool and ground tilt from a robust plane fit to the soil";
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
      ParamSpec::integer("max_surfaces", 1)
          .range(1, 8)
          .describe(
              "ground pieces fitted in turn (steps, ridges); the one the tool stands on wins"),
      ParamSpec::number("tool_area_mm", 0.0)
          .range(0, 10000)
          .in_unit("mm")
          .describe("the ground within about this distance of the tool point picks its piece; "
                    "0 = the largest piece"),
      ParamSpec::number("outlier_threshold_mm", 10.0)
          .range(0.1, 1000)
          .in_unit("mm")
          .describe("soil points farther than this from the surface (along Z) are outliers"),
      ParamSpec::integer("iterations", 64)
          .range(1, 10000)
          .describe("RANSAC hypotheses (3-point planes) tried before the least-squares re-fits"),
      ParamSpec::number("min_inlier_fraction", 0.5)
          .range(0, 1)
          .describe("below this fraction of the soil points (weighed by their votes) on the "
                    "tool's surface the measurement is invalid"),
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
