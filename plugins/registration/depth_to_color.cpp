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
      cx_half_(static_cast<float>(rig.color.cx + 0.5)),
      cy_half_(static_cast<float>(rig.color.cy + 0.5)),
      distorted_(rig.color.has_distortion()),
      max_radius2_(fold_radius2(rig.color.distortion)) {
  for (int i = 0; i < 9; ++i) {
    r_[i / 3][i % 3] = static_cast<float>(rig.depth_to_color_r(i / 3, i % 3));
  }
  for (int i = 0; i < 3; ++i) t_mm_[i] = static_cast<float>(rig.depth_to_color_t_mm[i]);
  // Without colour distortion, u + 0.5 = (fx X + (cx + 0.5) Z) / Z for the point
  // (X, Y, Z) = R P + T: the numerator is (fx R_0 + (cx + 0.5) R_2) P + fx T_x + (cx + 0.5) T_z.
  const double cx_half = rig.color.cx + 0.5;
  const double cy_half = rig.color.cy + 0.5;
  for (int j = 0; j < 3; ++j) {
    u_numerator_[j] = static_cast<float>(rig.color.fx * rig.depth_to_color_r(0, j) +
                                         cx_half * rig.depth_to_color_r(2, j));
    v_numerator_[j] = static_cast<float>(rig.color.fy * rig.depth_to_color_r(1, j) +
                                         cy_half * rig.depth_to_color_r(2, j));
  }
  u_numerator_t_ = static_cast<float>(rig.color.fx * rig.depth_to_color_t_mm[0] +
                                      cx_half * rig.depth_to_color_t_mm[2]);
  v_numerator_t_ = static_cast<float>(rig.color.fy * rig.depth_to_color_t_mm[1] +
                                      cy_half * rig.depth_to_color_t_mm[2]);
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

// Compile-time variants keep the per-vector loop free of branches.
template <class Store>
void DepthToColor::project(int row, const float* z_mm, const Store& store) const {
  if (separable_) {
    distorted_ ? project<true, true>(row, z_mm, store) : project<true, false>(row, z_mm, store);
  } else {
    distorted_ ? project<false, true>(row, z_mm, store) : project<false, false>(row, z_mm, store);
  }
}

void DepthToColor::project_row(int row, const float* z_mm, float* color_u, float* color_v,
                               float* color_depth) const {
  const cv::v_float32x4 half = cv::v_setall_f32(0.5f);
  const cv::v_float32x4 not_shown = cv::v_setall_f32(std::numeric_limits<float>::quiet_NaN());
  project(row, z_mm,
          [&](int i, const auto& u_half, const auto& v_half, const auto& depth, const auto& shown) {
            cv::v_store(color_u + i, u_half - half);
            cv::v_store(color_v + i, v_half - half);
            cv::v_store(color_depth + i, cv::v_select(shown(), depth, not_shown));
          });
}

void DepthToColor::locate_row(int row, const float* z_mm, const CellGrid& cells,
                              std::int32_t* color_pixel, std::int32_t* cell,
                              float* color_depth) const {
  using cv::v_float32x4;
  const v_float32x4 half = cv::v_setall_f32(0.5f);
  const v_float32x4 width = cv::v_setall_f32(static_cast<float>(color_width_));
  const v_float32x4 per_cell = cv::v_setall_f32(1.0f / static_cast<float>(cells.size));
  const v_float32x4 columns = cv::v_setall_f32(static_cast<float>(cells.columns));
  const cv::v_int32x4 none = cv::v_setall_s32(-1);
  project(row, z_mm,
          [&](int i, const auto& u_half, const auto& v_half, const auto& depth, const auto& shown) {
            // Shown points have 0 <= u + 0.5 < width: truncation rounds to the nearest pixel.
            // Whole numbers below 2^24 are exact in float, and (x + 0.5) / size lies at least
            // 0.5 / size from a whole number, so truncation gives x / size exactly.
            const v_float32x4 x = cv::v_cvt_f32(cv::v_trunc(u_half));
            const v_float32x4 y = cv::v_cvt_f32(cv::v_trunc(v_half));
            const v_float32x4 cell_x = cv::v_cvt_f32(cv::v_trunc((x + half) * per_cell));
            const v_float32x4 cell_y = cv::v_cvt_f32(cv::v_trunc((y + half) * per_cell));
            const cv::v_int32x4 visible = cv::v_reinterpret_as_s32(shown());
            cv::v_store(color_pixel + i,
                        cv::v_select(visible, cv::v_trunc(cv::v_muladd(y, width, x)), none));
            cv::v_store(
                cell + i,
                cv::v_select(visible, cv::v_trunc(cv::v_muladd(cell_y, columns, cell_x)), none));
            cv::v_store(color_depth + i, depth);
          });
}

void DepthToColor::color_depth_row(int row, const float* z_mm, float* color_depth) const {
  project(row, z_mm, [&](int i, const auto&, const auto&, const auto& depth, const auto&) {
    cv::v_store(color_depth + i, depth);
  });
}

// `store(i, u + 0.5, v + 0.5, depth, shown)` takes the results for the vector of pixels
// from i on; shown() is computed on demand, and what a store does not use the compiler
// leaves out (for color_depth_row: all but the depth).
template <bool kSeparable, bool kDistorted, class Store>
void DepthToColor::project(int row, const float* z_mm, const Store& store) const {
  using cv::v_float32x4;
  const auto splat = [](float value) { return cv::v_setall_f32(value); };
  const std::size_t table_row = kSeparable ? 0 : static_cast<std::size_t>(row) * row_capacity_;
  const float* xs = x_.data() + table_row;
  const float* ys = y_.data() + table_row;
  // Without depth distortion y' is the row's: a row (a, b, c) of a matrix times
  // (x', y', 1) is a x' + (b y' + c), the bracket a constant of the row.
  const float row_y = kSeparable ? y_[static_cast<std::size_t>(row)] : 0.0f;
  const auto column = [&](const Row3& r) { return splat(r[0]); };
  const auto y_part = [&](const Row3& r) { return splat(r[1]); };
  const auto constant = [&](const Row3& r) { return splat(r[1] * row_y + r[2]); };
  const v_float32x4 z_offset = splat(z_offset_mm_);
  const v_float32x4 zero = splat(0.0f), one = splat(1.0f);
  const v_float32x4 u_end = splat(static_cast<float>(color_width_) - kEdgeMarginPx);
  const v_float32x4 v_end = splat(static_cast<float>(color_height_) - kEdgeMarginPx);
  const v_float32x4 max_radius2 = splat(max_radius2_);
  const v_float32x4 fx = splat(fx_), fy = splat(fy_);
  const v_float32x4 cx_half = splat(cx_half_), cy_half = splat(cy_half_);
  const v_float32x4 tx = splat(t_mm_[0]), ty = splat(t_mm_[1]), tz = splat(t_mm_[2]);
  const v_float32x4 u_numerator_t = splat(u_numerator_t_), v_numerator_t = splat(v_numerator_t_);
  const lens::Distortion<v_float32x4> distortion{
      splat(k_[0]), splat(k_[1]), splat(k_[2]), splat(k_[3]), splat(k_[4]), one, splat(2.0f)};
  // Rows of the matrices that take the ray (x', y', 1) to the point's z (rz), its x and y
  // (rx, ry: R's rows), or, without colour distortion, straight to u + 0.5 and v + 0.5
  // times z (K's rows folded into R's).
  const Row3& rz_row = r_[2];
  const Row3& rx_row = kDistorted ? r_[0] : u_numerator_;
  const Row3& ry_row = kDistorted ? r_[1] : v_numerator_;

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
    v_float32x4 rz = cv::v_muladd(column(rz_row), x, constant(rz_row));
    v_float32x4 rx = cv::v_muladd(column(rx_row), x, constant(rx_row));
    v_float32x4 ry = cv::v_muladd(column(ry_row), x, constant(ry_row));
    if constexpr (!kSeparable) {
      const v_float32x4 y = cv::v_load(ys + i);
      rz = cv::v_muladd(y_part(rz_row), y, rz);
      rx = cv::v_muladd(y_part(rx_row), y, rx);
      ry = cv::v_muladd(y_part(ry_row), y, ry);
    }
    // P_c = R * (depth * (x', y', 1)) + T
    const v_float32x4 pz = cv::v_muladd(depth, rz, tz);
    const v_float32x4 inverse = one / pz;
    v_float32x4 inside_fold = pz > zero;
    v_float32x4 u_half;
    v_float32x4 v_half;
    if constexpr (kDistorted) {
      v_float32x4 nx = cv::v_muladd(depth, rx, tx) * inverse;
      v_float32x4 ny = cv::v_muladd(depth, ry, ty) * inverse;
      inside_fold = inside_fold & (nx * nx + ny * ny <= max_radius2);
      distortion.apply(nx, ny);
      u_half = cv::v_muladd(fx, nx, cx_half);
      v_half = cv::v_muladd(fy, ny, cy_half);
    } else {
      u_half = cv::v_muladd(depth, rx, u_numerator_t) * inverse;
      v_half = cv::v_muladd(depth, ry, v_numerator_t) * inverse;
    }
    store(i, u_half, v_half, pz, [&] {
      return inside_fold & (u_half >= zero) & (u_half < u_end) & (v_half >= zero) &
             (v_half < v_end);
    });
  }
}

}  // namespace tilth::registration
