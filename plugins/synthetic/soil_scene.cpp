#include "soil_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace tilth::synthetic {
namespace {

// Reflectances (BGR) of the materials the preset does not choose: wet straw dark and
// close to the soil's hue.
const cv::Vec3f kWetStraw(0.14f, 0.22f, 0.30f);
const cv::Vec3f kStubble(0.32f, 0.60f, 0.72f);
const cv::Vec3f kWeathered(0.15f, 0.17f, 0.19f);  // grey, darker than the soil
constexpr double kClutterSigmaMm = 10.0;

cv::Vec3f reflectance(const std::array<double, 3>& bgr) {
  return {static_cast<float>(bgr[0]), static_cast<float>(bgr[1]), static_cast<float>(bgr[2])};
}

cv::Vec3b to_bytes(const cv::Vec3f& reflectance) {
  return {cv::saturate_cast<std::uint8_t>(reflectance[0] * 255.0f),
          cv::saturate_cast<std::uint8_t>(reflectance[1] * 255.0f),
          cv::saturate_cast<std::uint8_t>(reflectance[2] * 255.0f)};
}

}  // namespace

SoilScene::SoilScene(const ScenePreset& preset, double soil_z_mm, cv::Rect2d area, double cell_mm,
                     std::uint64_t seed)
    : preset_(preset), soil_z_(static_cast<float>(soil_z_mm)), area_(area), cell_mm_(cell_mm) {
  const int cols = static_cast<int>(std::ceil(area.width / cell_mm));
  const int rows = static_cast<int>(std::ceil(area.height / cell_mm));
  cv::RNG rng(seed);
  soil_height_.create(rows, cols, CV_32FC1);
  material_ = cv::Mat(rows, cols, CV_8UC1, cv::Scalar(static_cast<int>(Material::kSoil)));
  albedo_.create(rows, cols, CV_8UC3);
  add_soil(rng);
  if (preset.crack_mm > 0.0) add_cracks(rng);
  height_ = soil_height_.clone();
  add_stubble(rng);
  add_straws(rng);
  if (preset.multipath > 0.0) {
    cv::subtract(height_, soil_height_, clutter_);
    cv::GaussianBlur(clutter_, clutter_, cv::Size(0, 0), kClutterSigmaMm / cell_mm);
  }
  double highest = 0.0;
  cv::minMaxLoc(height_, nullptr, &highest);
  top_z_ = soil_z_ - static_cast<float>(highest);
}

float SoilScene::soil_z(double x, double y) const {
  const int c = cell_x(x);
  const int r = cell_y(y);
  if (c < 0 || r < 0 || c >= soil_height_.cols || r >= soil_height_.rows) return soil_z_;
  return soil_z_ - soil_height_.at<float>(r, c);
}

double SoilScene::ground_height_mm(double x, double y) const {
  constexpr double kDegree = CV_PI / 180.0;
  double h =
      -y * std::tan(preset_.tilt_x_deg * kDegree) - x * std::tan(preset_.tilt_y_deg * kDegree);
  if (preset_.ridge_mm > 0.0) {
    const double angle = preset_.ridge_angle_deg * kDegree;
    const double across = x * std::cos(angle) + y * std::sin(angle);
    h += 0.5 * preset_.ridge_mm * std::cos(2 * CV_PI * across / preset_.ridge_period_mm);
  }
  if (!preset_.layers_mm.empty()) {
    const double segment = preset_.track_length_mm / static_cast<double>(preset_.layers_mm.size());
    const int layer = std::clamp(static_cast<int>(std::floor(x / segment)), 0,
                                 static_cast<int>(preset_.layers_mm.size()) - 1);
    h += preset_.layers_mm[layer];
  }
  return h;
}

float SoilScene::clutter_mm(double x, double y) const {
  if (clutter_.empty()) return 0.0f;
  const int c = std::clamp(cell_x(x), 0, clutter_.cols - 1);
  const int r = std::clamp(cell_y(y), 0, clutter_.rows - 1);
  return clutter_.at<float>(r, c);
}

Material SoilScene::material(double x, double y) const {
  const int c = cell_x(x);
  const int r = cell_y(y);
  if (c < 0 || r < 0 || c >= material_.cols || r >= material_.rows) return Material::kSoil;
  return static_cast<Material>(material_.at<std::uint8_t>(r, c));
}

cv::Vec3f SoilScene::albedo(double x, double y) const {
  const int c = std::clamp(cell_x(x), 0, albedo_.cols - 1);
  const int r = std::clamp(cell_y(y), 0, albedo_.rows - 1);
  const cv::Vec3b bytes = albedo_.at<cv::Vec3b>(r, c);
  return {bytes[0] / 255.0f, bytes[1] / 255.0f, bytes[2] / 255.0f};
}

// Micro-relief: a few sinusoids with wavelengths of 15-80 mm (many periods over a region
// of interest, so its mean there is the datum) plus fine roughness, on the ground's shape
// (tilt, ridges, the track's layers); soil colour varies slowly with clods and moisture.
void SoilScene::add_soil(cv::RNG& rng) {
  struct Wave {
    double kx, ky, phase, amplitude;
  };
  std::vector<Wave> waves;
  for (int i = 0; i < 6; ++i) {
    const double wavelength = rng.uniform(15.0, 80.0);
    const double angle = rng.uniform(0.0, CV_PI);
    waves.push_back({2 * CV_PI / wavelength * std::cos(angle),
                     2 * CV_PI / wavelength * std::sin(angle), rng.uniform(0.0, 2 * CV_PI),
                     preset_.relief_mm / 3.0});
  }
  cv::Mat roughness(soil_height_.size(), CV_32FC1);
  rng.fill(roughness, cv::RNG::NORMAL, 0.0, preset_.relief_mm * 0.15);
  cv::Mat tint(soil_height_.size(), CV_32FC1);
  rng.fill(tint, cv::RNG::NORMAL, 0.0, 1.0);
  cv::GaussianBlur(tint, tint, cv::Size(0, 0), 6.0 / cell_mm_);
  cv::normalize(tint, tint, -0.18, 0.18, cv::NORM_MINMAX);
  const cv::Vec3f soil = reflectance(preset_.soil_bgr);
  for (int r = 0; r < soil_height_.rows; ++r) {
    const double y = area_.y + (r + 0.5) * cell_mm_;
    for (int c = 0; c < soil_height_.cols; ++c) {
      const double x = area_.x + (c + 0.5) * cell_mm_;
      double h = roughness.at<float>(r, c) + ground_height_mm(x, y);
      for (const auto& wave : waves)
        h += wave.amplitude * std::sin(wave.kx * x + wave.ky * y + wave.phase);
      soil_height_.at<float>(r, c) = static_cast<float>(h);
      albedo_.at<cv::Vec3b>(r, c) = to_bytes(soil * (1.0f + tint.at<float>(r, c)));
    }
  }
}

// Cracks along the borders of a Voronoi tessellation (clods around jittered seeds on a
// grid of crack_spacing_mm): V-shaped, crack_mm deep at the border, to nothing
// crack_width_mm / 2 either side of it; each crack's depth varies from half to all of it.
void SoilScene::add_cracks(cv::RNG& rng) {
  const double spacing = preset_.crack_spacing_mm;
  const int across = static_cast<int>(std::ceil(area_.width / spacing)) + 2;
  const int down = static_cast<int>(std::ceil(area_.height / spacing)) + 2;
  struct Seed {
    double x, y, depth;
  };
  std::vector<Seed> seeds;
  for (int j = 0; j < down; ++j) {
    for (int i = 0; i < across; ++i) {
      seeds.push_back({area_.x + (i + rng.uniform(-0.5, 0.5)) * spacing,
                       area_.y + (j + rng.uniform(-0.5, 0.5)) * spacing,
                       preset_.crack_mm * rng.uniform(0.5, 1.0)});
    }
  }
  const double half_width = preset_.crack_width_mm / 2;
  for (int r = 0; r < soil_height_.rows; ++r) {
    const double y = area_.y + (r + 0.5) * cell_mm_;
    const int j = std::clamp(static_cast<int>(std::lround((y - area_.y) / spacing)), 0, down - 1);
    for (int c = 0; c < soil_height_.cols; ++c) {
      const double x = area_.x + (c + 0.5) * cell_mm_;
      const int i =
          std::clamp(static_cast<int>(std::lround((x - area_.x) / spacing)), 0, across - 1);
      // Each seed lies within half a spacing of its grid point: the nearest seed, and the
      // neighbours whose borders with its clod pass near the pixel, lie among the 5x5 grid
      // points around the pixel's.
      std::array<const Seed*, 25> candidates{};
      std::size_t count = 0;
      for (int row = std::max(j - 2, 0); row <= std::min(j + 2, down - 1); ++row) {
        for (int col = std::max(i - 2, 0); col <= std::min(i + 2, across - 1); ++col) {
          candidates[count++] = &seeds[static_cast<std::size_t>(row * across + col)];
        }
      }
      const auto squared_distance = [&](const Seed* seed) {
        return (x - seed->x) * (x - seed->x) + (y - seed->y) * (y - seed->y);
      };
      const Seed* nearest = *std::min_element(
          candidates.begin(), candidates.begin() + count,
          [&](const Seed* a, const Seed* b) { return squared_distance(a) < squared_distance(b); });
      // The nearest border of its clod: the pixel's distance to the bisector between the
      // nearest seed and each other.
      double border = std::numeric_limits<double>::max();
      double depth = 0.0;
      for (std::size_t k = 0; k < count; ++k) {
        const Seed* other = candidates[k];
        if (other == nearest) continue;
        const double to_bisector = (squared_distance(other) - squared_distance(nearest)) /
                                   (2 * std::hypot(other->x - nearest->x, other->y - nearest->y));
        if (to_bisector < border) {
          border = to_bisector;
          depth = std::min(nearest->depth, other->depth);
        }
      }
      if (border >= half_width) continue;
      depth *= 1.0 - border / half_width;
      soil_height_.at<float>(r, c) -= static_cast<float>(depth);
    }
  }
}

// Standing stalks: discs of 3-5 mm diameter, of the preset's heights (cut wheat stubble:
// 60-70 mm).
void SoilScene::add_stubble(cv::RNG& rng) {
  for (int i = 0; i < preset_.stubble; ++i) {
    const double cx = rng.uniform(area_.x, area_.x + area_.width);
    const double cy = rng.uniform(area_.y, area_.y + area_.height);
    const double radius = rng.uniform(1.5, 2.5);
    const double top = preset_.stubble_height_mm + rng.uniform(-preset_.stubble_height_spread_mm,
                                                               preset_.stubble_height_spread_mm);
    const float shade = static_cast<float>(rng.uniform(0.85, 1.1));
    for (int r = cell_y(cy - radius); r <= cell_y(cy + radius); ++r) {
      for (int c = cell_x(cx - radius); c <= cell_x(cx + radius); ++c) {
        if (r < 0 || c < 0 || r >= height_.rows || c >= height_.cols) continue;
        const double x = area_.x + (c + 0.5) * cell_mm_ - cx;
        const double y = area_.y + (r + 0.5) * cell_mm_ - cy;
        if (x * x + y * y > radius * radius) continue;
        const float h = soil_height_.at<float>(r, c) + static_cast<float>(top);
        if (h <= height_.at<float>(r, c)) continue;
        height_.at<float>(r, c) = h;
        material_.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(Material::kStubble);
        albedo_.at<cv::Vec3b>(r, c) = to_bytes(kStubble * shade);
      }
    }
  }
}

// Lying straws: cylinders of the preset's diameters and lengths at random angles.
// Each rests on the soil or the highest straw under its axis, so straws stack where
// they cross; standing stubble pokes through them rather than holding them up (a
// height field cannot show a straw floating on a stalk). The first-laid straws, which end
// up at the bottom, are weathered when the preset says so.
void SoilScene::add_straws(cv::RNG& rng) {
  const cv::Vec3f fresh = preset_.wet_straw ? kWetStraw : reflectance(preset_.straw_bgr);
  const int weathered = static_cast<int>(preset_.weathered_fraction * preset_.straws);
  cv::Mat lying = soil_height_.clone();
  for (int i = 0; i < preset_.straws; ++i) {
    const cv::Vec3f colour = i < weathered ? kWeathered : fresh;
    const double cx = rng.uniform(area_.x, area_.x + area_.width);
    const double cy = rng.uniform(area_.y, area_.y + area_.height);
    const double angle = rng.uniform(0.0, CV_PI);
    const double half = rng.uniform(preset_.straw_length_mm[0] / 2, preset_.straw_length_mm[1] / 2);
    const double radius = rng.uniform(preset_.straw_radius_mm[0], preset_.straw_radius_mm[1]);
    const float shade = static_cast<float>(rng.uniform(0.8, 1.15));
    const double ux = std::cos(angle);
    const double uy = std::sin(angle);
    double base = 0.0;
    for (double s = -half; s <= half; s += cell_mm_) {
      const int c = cell_x(cx + s * ux);
      const int r = cell_y(cy + s * uy);
      if (r >= 0 && c >= 0 && r < lying.rows && c < lying.cols) {
        base = std::max(base, static_cast<double>(lying.at<float>(r, c)));
      }
    }
    const double extent = half + radius;
    for (int r = cell_y(cy - extent); r <= cell_y(cy + extent); ++r) {
      for (int c = cell_x(cx - extent); c <= cell_x(cx + extent); ++c) {
        if (r < 0 || c < 0 || r >= height_.rows || c >= height_.cols) continue;
        const double x = area_.x + (c + 0.5) * cell_mm_ - cx;
        const double y = area_.y + (r + 0.5) * cell_mm_ - cy;
        const double along = x * ux + y * uy;
        const double across = -x * uy + y * ux;
        if (std::abs(along) > half || std::abs(across) >= radius) continue;
        const float h =
            static_cast<float>(base + radius + std::sqrt(radius * radius - across * across));
        lying.at<float>(r, c) = std::max(lying.at<float>(r, c), h);
        if (h <= height_.at<float>(r, c)) continue;
        height_.at<float>(r, c) = h;
        material_.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(Material::kStraw);
        // Rounded straw is darker towards its sides.
        const float side =
            static_cast<float>(0.75 + 0.25 * std::sqrt(1.0 - across * across / (radius * radius)));
        albedo_.at<cv::Vec3b>(r, c) = to_bytes(colour * (shade * side));
      }
    }
  }
}

}  // namespace tilth::synthetic
