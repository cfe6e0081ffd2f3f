#include "ray_caster.h"

#include <cmath>

namespace tilth::synthetic {
namespace {

// Steps in z small enough that a 3 mm straw is not stepped over by an oblique ray, then
// bisection to 1/256 of a step.
constexpr double kStepMm = 1.0;
constexpr int kBisections = 8;

}  // namespace

SurfaceHit cast_ray(const SoilScene& scene, const cv::Vec3d& origin, const cv::Vec3d& direction,
                    double shift_x_mm) {
  auto below_surface = [&](double z) {
    const double t = z - origin[2];
    return z >=
           scene.surface_z(origin[0] + t * direction[0] + shift_x_mm, origin[1] + t * direction[1]);
  };
  double above = scene.top_z() - kStepMm;
  double z = above;
  while (!below_surface(z)) {
    above = z;
    z += kStepMm;
  }
  double below = z;
  for (int i = 0; i < kBisections; ++i) {
    const double middle = 0.5 * (above + below);
    (below_surface(middle) ? below : above) = middle;
  }
  const double t = below - origin[2];
  const double x = origin[0] + t * direction[0] + shift_x_mm;
  const double y = origin[1] + t * direction[1];
  // On the flat parts, take the surface's exact depth rather than the bisection's.
  const double surface = scene.surface_z(x, y);
  const double exact_t = std::abs(surface - below) < 1e-2 ? surface - origin[2] : t;
  return {exact_t * cv::norm(direction), origin[2] + exact_t, x, y, scene.material(x, y)};
}

Lighting::Lighting(const ScenePreset& preset)
    : sky_bgr(static_cast<float>(preset.sky_bgr[0]), static_cast<float>(preset.sky_bgr[1]),
              static_cast<float>(preset.sky_bgr[2])),
      shadows(preset.shadows) {
  constexpr double kDegree = CV_PI / 180.0;
  const double elevation = preset.sun_elevation_deg * kDegree;
  const double azimuth = preset.sun_azimuth_deg * kDegree;
  to_sun = {std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
            -std::sin(elevation)};
}

cv::Vec3f sunlight(const SoilScene& scene, const SurfaceHit& hit, const Lighting& lighting) {
  constexpr double kDelta = 0.5;
  const double dzdx = (scene.surface_z(hit.x_mm + kDelta, hit.y_mm) -
                       scene.surface_z(hit.x_mm - kDelta, hit.y_mm)) /
                      (2 * kDelta);
  const double dzdy = (scene.surface_z(hit.x_mm, hit.y_mm + kDelta) -
                       scene.surface_z(hit.x_mm, hit.y_mm - kDelta)) /
                      (2 * kDelta);
  // Surface z(x, y); its normal pointing up (towards -z).
  const cv::Vec3d normal = cv::normalize(cv::Vec3d(dzdx, dzdy, -1.0));
  const auto direct = static_cast<float>(std::max(0.0, normal.dot(lighting.to_sun)));
  const cv::Vec3f lit = lighting.sky_bgr + (cv::Vec3f::all(1.0f) - lighting.sky_bgr) * direct;
  if (direct == 0.0f || !lighting.shadows) return lit;
  // March towards the sun until the ray is above everything.
  const double top = scene.top_z();
  for (double s = 1.0;; s += 1.0) {
    const cv::Vec3d p = cv::Vec3d(hit.x_mm, hit.y_mm, hit.z_mm) + s * lighting.to_sun;
    if (p[2] < top) break;
    if (scene.surface_z(p[0], p[1]) < p[2] - 0.25) return lighting.sky_bgr;
  }
  return lit;
}

}  // namespace tilth::synthetic
