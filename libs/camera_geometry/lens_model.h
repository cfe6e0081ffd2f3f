// The camera lens model shared by the depth and registration stages: OpenCV's
// distortion (k1, k2, p1, p2, k3) applied forward, and its inverse for whole pixel
// grids, computed once per calibration.
#pragma once

#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "tilth/calibration.h"

namespace tilth::lens {

// OpenCV's distortion on normalised coordinates. T is a scalar or a GCC vector type
// (the registration's kernels), hence the constants 1 and 2 as members.
template <class T>
struct Distortion {
  T k1, k2, p1, p2, k3;
  T one, two;

  // Undistorted (x, y) -> distorted, in place. Always inlined: vector code compiled for
  // several instruction sets must not share one out-of-line copy.
  [[gnu::always_inline]] void apply(T& x, T& y) const {
    const T r2 = x * x + y * y;
    const T radial = one + r2 * (k1 + r2 * (k2 + r2 * k3));
    const T two_xy = two * x * y;
    const T xd = x * radial + p1 * two_xy + p2 * (r2 + two * x * x);
    const T yd = y * radial + p1 * (r2 + two * y * y) + p2 * two_xy;
    x = xd;
    y = yd;
  }
};

inline Distortion<double> distortion_of(const CameraIntrinsics& camera) {
  const auto& c = camera.distortion;
  return {c[0], c[1], c[2], c[3], c[4], 1.0, 2.0};
}

// The undistorted normalised coordinates (x', y') of the given pixels (0-based, (0,0) at
// the centre of the top-left pixel). Throws tilth::Error naming `where` (the
// calibration field, e.g. "rig.calib.json:/depth_camera/distortion") when the
// distortion cannot be inverted at one of them.
std::vector<cv::Point2d> undistort(const CameraIntrinsics& camera,
                                   const std::vector<cv::Point2d>& pixels,
                                   const std::string& where);

// (x', y') of every pixel of the camera: CV_64FC2, camera.height x camera.width.
cv::Mat undistorted_pixel_grid(const CameraIntrinsics& camera, const std::string& where);

}  // namespace tilth::lens
