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

// The sun and the sky of a preset.
struct Lighting {
  explicit Lighting(const ScenePreset& preset);

  cv::Vec3d to_sun;   // unit vector in the camera frame (up is -z)
  cv::Vec3f sky_bgr;  // the light where the sun does not reach, relative to the sun's
  bool shadows;
};

// Diffuse light (BGR) at a hit: the sky's plus the sun's, unless the surface towards the
// sun hides it.
cv::Vec3f sunlight(const SoilScene& scene, const SurfaceHit& hit, const Lighting& lighting);

}  // namespace tilth::synthetic
