#include "depth_to_color.h"

#include <algorithm>
#include <limits>

#include "camera_geometry/lens_model.h"

namespace tilth::registration {
namespace {

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

DepthToColor::DepthToColor(const RigCalibration& rig, const std::string& file,
                           const RowKernels& kernels)
    : model_{.depth_width = rig.depth.width,
             .row_capacity = (rig.depth.width + kRowLanes - 1) / kRowLanes * kRowLanes,
             .color_width = rig.color.width,
             .color_height = rig.color.height,
             .r = {},
             .t_mm = {},
             .z_offset_mm = static_cast<float>(rig.depth.z_offset_mm),
             .fx = static_cast<float>(rig.color.fx),
             .fy = static_cast<float>(rig.color.fy),
             .cx = static_cast<float>(rig.color.cx),
             .cy = static_cast<float>(rig.color.cy),
             .distorted = rig.color.has_distortion(),
             .k = {},
             .max_radius2 = fold_radius2(rig.color.distortion),
             .edge_margin_px = kEdgeMarginPx},
      depth_height_(rig.depth.height),
      kernels_(kernels),
      separable_(!rig.depth.has_distortion()) {
  for (int i = 0; i < 9; ++i) model_.r[i] = static_cast<float>(rig.depth_to_color_r(i / 3, i % 3));
  for (int i = 0; i < 3; ++i) model_.t_mm[i] = static_cast<float>(rig.depth_to_color_t_mm[i]);
  for (int i = 0; i < 5; ++i) model_.k[i] = static_cast<float>(rig.color.distortion[i]);
  const int capacity = model_.row_capacity;
  const int width = model_.depth_width;
  // Padding lanes get x' = 0: a finite ray, whose results nobody reads.
  if (separable_) {
    x_.assign(static_cast<std::size_t>(capacity), 0.0f);
    for (int u = 0; u < width; ++u) {
      x_[u] = static_cast<float>((u - rig.depth.cx) / rig.depth.fx);
    }
    for (int v = 0; v < depth_height_; ++v) {
      y_.push_back(static_cast<float>((v - rig.depth.cy) / rig.depth.fy));
    }
    return;
  }
  const cv::Mat normalised =
      lens::undistorted_pixel_grid(rig.depth, file + ":/depth_camera/distortion");
  x_.assign(static_cast<std::size_t>(capacity) * depth_height_, 0.0f);
  y_.assign(x_.size(), 0.0f);
  for (int v = 0; v < depth_height_; ++v) {
    const auto* xy = normalised.ptr<cv::Vec2d>(v);
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * capacity + u;
      x_[i] = static_cast<float>(xy[u][0]);
      y_[i] = static_cast<float>(xy[u][1]);
    }
  }
}

void DepthToColor::project_row(int row, const float* z_mm, float* color_u, float* color_v,
                               float* color_depth) const {
  if (separable_) {
    kernels_.project(model_, x_.data(), nullptr, y_[static_cast<std::size_t>(row)], z_mm, color_u,
                     color_v, color_depth);
  } else {
    const std::size_t start = static_cast<std::size_t>(row) * model_.row_capacity;
    kernels_.project(model_, x_.data() + start, y_.data() + start, 0.0f, z_mm, color_u, color_v,
                     color_depth);
  }
}

}  // namespace tilth::registration
