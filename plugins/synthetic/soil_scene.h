// A soil surface with crop residue on it, as a height field over the ground: what both
// simulated cameras look at. Coordinates are the ToF camera frame (x right, y down,
// z along the optical axis towards the ground, mm); the ground may slide along x.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "scene_preset.h"

namespace tilth::synthetic {

enum class Material : std::uint8_t { kSoil = 0, kStraw = 1, kStubble = 2 };

class SoilScene {
 public:
  // `soil_z_mm` is the optical-centre depth of the soil datum; `area` the ground the
  // cameras can see (x, y in mm, the whole track for moving ground).
  SoilScene(const ScenePreset& preset, double soil_z_mm, cv::Rect2d area, double cell_mm,
            std::uint64_t seed);

  // Depth (camera z) of the surface at ground point (x, y); flat soil outside the area.
  float surface_z(double x, double y) const {
    const int c = cell_x(x);
    const int r = cell_y(y);
    if (c < 0 || r < 0 || c >= height_.cols || r >= height_.rows) return soil_z_;
    return soil_z_ - height_.at<float>(r, c);
  }
  // Depth of the soil alone (without residue) at (x, y).
  float soil_z(double x, double y) const;
  // Height of the ground's shape (tilt, ridges, layers; no micro-relief) above the datum
  // at (x, y): what the ground truth follows.
  double ground_height_mm(double x, double y) const;
  // How much residue stands around (x, y): its height above the soil, averaged over about
  // 10 mm (what multipath in a ToF pixel there sees).
  float clutter_mm(double x, double y) const;
  Material material(double x, double y) const;
  cv::Vec3f albedo(double x, double y) const;  // BGR reflectance, 0..1
  // The nearest surface depth anywhere: rays start marching just above it.
  float top_z() const { return top_z_; }

 private:
  int cell_x(double x) const { return static_cast<int>(std::floor((x - area_.x) / cell_mm_)); }
  int cell_y(double y) const { return static_cast<int>(std::floor((y - area_.y) / cell_mm_)); }
  void add_soil(cv::RNG& rng);
  void add_cracks(cv::RNG& rng);
  void add_stubble(cv::RNG& rng);
  void add_straws(cv::RNG& rng);

  const ScenePreset preset_;
  float soil_z_;
  cv::Rect2d area_;
  double cell_mm_;
  cv::Mat soil_height_;  // CV_32F, mm above the datum: relief and layers
  cv::Mat height_;       // CV_32F, mm above the datum: soil and residue
  cv::Mat material_;     // CV_8U, Material
  cv::Mat albedo_;       // CV_8UC3, BGR reflectance * 255
  cv::Mat clutter_;      // CV_32F, mm: residue height above the soil, blurred
  float top_z_;
};

}  // namespace tilth::synthetic
