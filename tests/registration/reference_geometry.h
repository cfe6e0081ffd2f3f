// The tests' own rig geometry in long double, written from docs/formats/calibration.md without
// the plugin's code: what the registration must agree with.
#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace tilth::registration::reference {

using Real = long double;

struct Vec3 {
  Real x, y, z;
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(Real s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline Real dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

struct Camera {
  int width, height;
  Real fx, fy, cx, cy;
  std::array<Real, 5> k;  // k1 k2 p1 p2 k3
};

struct Rig {
  Camera depth, color;
  Real r[3][3];
  Vec3 t;
  Real z_offset;
};

inline Camera camera_from(const nlohmann::json& c) {
  Camera camera{c["width"], c["height"], c["fx"], c["fy"], c["cx"], c["cy"], {}};
  if (c.contains("distortion")) {
    for (int i = 0; i < 5; ++i) camera.k[i] = c["distortion"][i].get<double>();
  }
  return camera;
}

inline Rig rig_from(const nlohmann::json& document) {
  Rig rig{camera_from(document["depth_camera"]), camera_from(document["color_camera"]), {}, {}, 0};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) rig.r[i][j] = document["depth_to_color"]["R"][i][j].get<double>();
  }
  const auto& t = document["depth_to_color"]["T_mm"];
  rig.t = {t[0].get<double>(), t[1].get<double>(), t[2].get<double>()};
  rig.z_offset = document["depth_camera"]["z_offset_mm"].get<double>();
  return rig;
}

struct Point2 {
  Real x, y;
};

inline Point2 distort(const std::array<Real, 5>& k, Point2 p) {
  const Real r2 = p.x * p.x + p.y * p.y;
  const Real radial = 1 + k[0] * r2 + k[1] * r2 * r2 + k[4] * r2 * r2 * r2;
  return {p.x * radial + 2 * k[2] * p.x * p.y + k[3] * (r2 + 2 * p.x * p.x),
          p.y * radial + k[2] * (r2 + 2 * p.y * p.y) + 2 * k[3] * p.x * p.y};
}

// Normalised undistorted coordinates of a pixel, by fixed-point iteration run to
// convergence (long double, far more iterations than moderate distortion needs).
inline Point2 undistort(const Camera& camera, Real u, Real v) {
  const Point2 target{(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy};
  Point2 p = target;
  for (int i = 0; i < 500; ++i) {
    const Point2 d = distort(camera.k, p);
    if (std::hypot(d.x - target.x, d.y - target.y) < 1e-16L) return p;
    p = {p.x + (target.x - d.x), p.y + (target.y - d.y)};
  }
  throw std::runtime_error("reference undistortion did not converge");
}

inline Vec3 depth_ray(const Rig& rig, int u, int v) {
  const Point2 p = undistort(rig.depth, u, v);
  return {p.x, p.y, 1};
}

inline Vec3 to_color(const Rig& rig, Vec3 p) {
  return Vec3{rig.r[0][0] * p.x + rig.r[0][1] * p.y + rig.r[0][2] * p.z,
              rig.r[1][0] * p.x + rig.r[1][1] * p.y + rig.r[1][2] * p.z,
              rig.r[2][0] * p.x + rig.r[2][1] * p.y + rig.r[2][2] * p.z} +
         rig.t;
}

// The colour camera's centre in the ToF frame: -R^T T.
inline Vec3 color_centre(const Rig& rig) {
  return {-(rig.r[0][0] * rig.t.x + rig.r[1][0] * rig.t.y + rig.r[2][0] * rig.t.z),
          -(rig.r[0][1] * rig.t.x + rig.r[1][1] * rig.t.y + rig.r[2][1] * rig.t.z),
          -(rig.r[0][2] * rig.t.x + rig.r[1][2] * rig.t.y + rig.r[2][2] * rig.t.z)};
}

struct ColorPixel {
  Real u, v;
  Real depth;    // along the colour camera's axis
  Real radius2;  // squared normalised radius before distortion
};

// The depth pixel with this ray (depth_ray) at z mm from the mounting surface, seen by
// the colour camera.
inline ColorPixel project(const Rig& rig, Vec3 ray, Real z) {
  const Vec3 p = to_color(rig, (z + rig.z_offset) * ray);
  const Point2 n{p.x / p.z, p.y / p.z};
  const Point2 d = distort(rig.color.k, n);
  return {rig.color.fx * d.x + rig.color.cx, rig.color.fy * d.y + rig.color.cy, p.z,
          n.x * n.x + n.y * n.y};
}

// Where a ray o + t d (t > 0) enters the box [lo, hi] (slab method).
inline std::optional<Real> enter_box(Vec3 o, Vec3 d, Vec3 lo, Vec3 hi) {
  Real enter = -INFINITY;
  Real leave = INFINITY;
  const Real os[3] = {o.x, o.y, o.z};
  const Real ds[3] = {d.x, d.y, d.z};
  const Real los[3] = {lo.x, lo.y, lo.z};
  const Real his[3] = {hi.x, hi.y, hi.z};
  for (int i = 0; i < 3; ++i) {
    const Real a = (los[i] - os[i]) / ds[i];
    const Real b = (his[i] - os[i]) / ds[i];
    enter = std::max(enter, std::min(a, b));
    leave = std::min(leave, std::max(a, b));
  }
  if (leave < std::max(enter, Real{0})) return std::nullopt;
  return enter;
}

}  // namespace tilth::registration::reference
