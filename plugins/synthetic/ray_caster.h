// Rays cast from a camera into a SoilScene: where they meet the surface, what they
// meet, and how brightly the sun lights it there.
#pragma once

#include <opencv2/core.hpp>

#include "soil_scene.h"

namespace tilth::synthetic {

struct SurfaceHit {
  double range_mm;  // from the ray's origin to the surface
  double z_mm;      // camera z of the hit
  double x_mm;      // ground coordinates of the hit
  double y_mm;
  Material material;
};

// `direction` has z = 1; `shift_x_mm` slides the ground under the camera.
SurfaceHit cast_ray(const SoilScene& scene, const cv::Vec3d& origin, const cv::Vec3d& direction,
                    double shift_x_mm);

// Diffuse light at a hit: ambient plus sun (unless the surface towards the sun hides it).
double sunlight(const SoilScene& scene, const SurfaceHit& hit, bool shadows);

}  // namespace tilth::synthetic
