#include "depth_to_color.h"

#include <algorithm>
#include <limits>

#include <opencv2/core/hal/intrin.hpp>

#include "lens_model.h"

namespace tilth::registration {
namespace {

constexpr int kLanes = 4;  // cv::v_float32x4

// The squared normalised radius at which the radial distortion r * (1 + k1 r^2 + k2 r^4 +
// k3 r^6) stops growing, i.e. where its derivative 1 + 3 k1 s + 5 k2 s^2 + 7 k3 s^3
// (s = r^2) first reaches 0; infinity when it does not within 84 degrees off axis.
float fold_radius2(const std::array<double, 5>& k) {
  constexpr double kStep = 1e-3;
  constexpr double kLargest = 100.0;  // r = 10: 84 degrees off axis
  for (double s = kStep; s < kLargest; s += kStep) {
    if (1.0 + s * (3.0 * k[0] + s * (5.0 * k[1] + s * 7.0 * k[4])) <= 0.0) {
      return static_cast<float>(s - kStep);
    }
  }
  return std::numeric_limits<float>::infinity();
}

}  // namespace

DepthToColor::DepthToColor(const RigCalibration& rig, const std::string& file)
    : depth_width_(rig.depth.width),
      depth_height_(rig.depth.height),
      color_width_(rig.color.width),
      color_height_(rig.color.height),
      row_capacity_((rig.depth.width + kLanes - 1) / kLanes * kLanes),
      separable_(!rig.depth.has_distortion()),
      z_offset_mm_(static_cast<float>(rig.depth.z_offset_mm)),
      fx_(static_cast<float>(rig.color.fx)),
      fy_(static_cast<float>(rig.color.fy)),
      cx_(static_cast<float>(rig.color.cx)),
      cy_(static_cast<float>(rig.color.cy)),
      distorted_(rig.color.has_distortion()),
      max_radius2_(fold_radius2(rig.color.distortion)) {
  for (int i = 0; i < 9; ++i) r_[i] = static_cast<float>(rig.depth_to_color_r(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) t_mm_[i] = static_cast<float>(rig.depth_to_color_t_mm[i]);
  for (int i = 0; i < 5; ++i) k_[i] = static_cast<float>(rig.color.distortion[i]);
  // Padding lanes get x' = 0: a finite ray, whose results nobody reads.
  if (separable_) {
    x_.assign(static_cast<std::size_t>(row_capacity_), 0.0f);
    for (int u = 0; u < depth_width_; ++u) {
      x_[u] = static_cast<float>((u - rig.depth.cx) / rig.depth.fx);
    }
    for (int v = 0; v < depth_height_; ++v) {
      y_.push_back(static_cast<float>((v - rig.depth.cy) / rig.depth.fy));
    }
    return;
  }
  const cv::Mat normalised =
      lens::undistorted_pixel_grid(rig.depth, file + ":/depth_camera/distortion");
  x_.assign(static_cast<std::size_t>(row_capacity_) * depth_height_, 0.0f);
  y_.assign(x_.size(), 0.0f);
  for (int v = 0; v < depth_height_; ++v) {
    const auto* xy = normalised.ptr<cv::Vec2d>(v);
    for (int u = 0; u < depth_width_; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * row_capacity_ + u;
      x_[i] = static_cast<float>(xy[u][0]);
      y_[i] = static_cast<float>(xy[u][1]);
    }
  }
}

void DepthToColor::project_row(int row, const float* z_mm, float* color_u, float* color_v,
                               float* color_depth) const {
  // Compile-time variants keep the per-vector loop free of branches.
  if (separable_) {
    distorted_ ? project<true, true>(row, z_mm, color_u, color_v, color_depth)
               : project<true, false>(row, z_mm, color_u, color_v, color_depth);
  } else {
    distorted_ ? project<false, true>(row, z_mm, color_u, color_v, color_depth)
               : project<false, false>(row, z_mm, color_u, color_v, color_depth);
  }
}

template <bool kSeparable, bool kDistorted>
void DepthToColor::project(int row, const float* z_mm, float* color_u, float* color_v,
                           float* color_depth) const {
  using cv::v_float32x4;
  const auto splat = [](float value) { return cv::v_setall_f32(value); };
  const std::size_t table_row = kSeparable ? 0 : static_cast<std::size_t>(row) * row_capacity_;
  const float* xs = x_.data() + table_row;
  const float* ys = y_.data() + table_row;
  // Without depth distortion y' is the row's: R * (x', y', 1) = column 0 * x' + a constant.
  const float row_y = kSeparable ? y_[static_cast<std::size_t>(row)] : 0.0f;
  const v_float32x4 r00 = splat(r_[0]), r01 = splat(r_[1]), r02 = splat(r_[1] * row_y + r_[2]);
  const v_float32x4 r10 = splat(r_[3]), r11 = splat(r_[4]), r12 = splat(r_[4] * row_y + r_[5]);
  const v_float32x4 r20 = splat(r_[6]), r21 = splat(r_[7]), r22 = splat(r_[7] * row_y + r_[8]);
  const v_float32x4 tx = splat(t_mm_[0]), ty = splat(t_mm_[1]), tz = splat(t_mm_[2]);
  const v_float32x4 z_offset = splat(z_offset_mm_);
  const v_float32x4 fx = splat(fx_), fy = splat(fy_), cx = splat(cx_), cy = splat(cy_);
  const v_float32x4 zero = splat(0.0f), one = splat(1.0f), minus_half = splat(-0.5f);
  const v_float32x4 u_end = splat(static_cast<float>(color_width_) - 0.5f - kEdgeMarginPx);
  const v_float32x4 v_end = splat(static_cast<float>(color_height_) - 0.5f - kEdgeMarginPx);
  const v_float32x4 max_radius2 = splat(max_radius2_);
  const v_float32x4 not_shown = splat(std::numeric_limits<float>::quiet_NaN());
  const lens::Distortion<v_float32x4> distortion{
      splat(k_[0]), splat(k_[1]), splat(k_[2]), splat(k_[3]), splat(k_[4]), one, splat(2.0f)};

  for (int i = 0; i < row_capacity_; i += kLanes) {
    v_float32x4 z;
    if (i + kLanes <= depth_width_) {
      z = cv::v_load(z_mm + i);
    } else {  // the row's last, partial vector: no reading past its end
      float tail[kLanes];
      std::fill(std::begin(tail), std::end(tail), std::numeric_limits<float>::quiet_NaN());
      std::copy(z_mm + i, z_mm + depth_width_, tail);
      z = cv::v_load(tail);
    }
    const v_float32x4 depth = z + z_offset;  // at the ToF optical centre
    const v_float32x4 x = cv::v_load(xs + i);
    v_float32x4 rx = cv::v_muladd(r00, x, r02);
    v_float32x4 ry = cv::v_muladd(r10, x, r12);
    v_float32x4 rz = cv::v_muladd(r20, x, r22);
    if constexpr (!kSeparable) {
      const v_float32x4 y = cv::v_load(ys + i);
      rx = cv::v_muladd(r01, y, rx);
      ry = cv::v_muladd(r11, y, ry);
      rz = cv::v_muladd(r21, y, rz);
    }
    // P_c = R * (depth * (x', y', 1)) + T
    const v_float32x4 pz = cv::v_muladd(depth, rz, tz);
    const v_float32x4 inverse = one / pz;
    v_float32x4 nx = cv::v_muladd(depth, rx, tx) * inverse;
    v_float32x4 ny = cv::v_muladd(depth, ry, ty) * inverse;
    v_float32x4 shown = pz > zero;
    if constexpr (kDistorted) {
      shown = shown & (nx * nx + ny * ny <= max_radius2);
      distortion.apply(nx, ny);
    }
    const v_float32x4 u = cv::v_muladd(fx, nx, cx);
    const v_float32x4 v = cv::v_muladd(fy, ny, cy);
    shown = shown & (u >= minus_half) & (u < u_end) & (v >= minus_half) & (v < v_end);
    cv::v_store(color_u + i, u);
    cv::v_store(color_v + i, v);
    cv::v_store(color_depth + i, cv::v_select(shown, pz, not_shown));
  }
}

}  // namespace tilth::registration
