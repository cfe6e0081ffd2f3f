// The soil surface under the residue, from depth alone, and each pixel's height above it.
// Residue lies on the soil, so the soil is the farthest surface the camera sees: a robust
// plane through the farthest depths (or, for ground that steps or curves, their envelope
// over a window wider than the residue), then a local surface that follows the relief.
#pragma once

#include <opencv2/core/mat.hpp>

#include "tilth/param_spec.h"

namespace tilth::segmentation {

class SoilSurface {
 public:
  // `height_mm`: pixels higher than this are residue, and not soil while the local
  // surface is fitted; a frame whose depth is noisier raises it with the noise, up to
  // `max_height_mm` (soil lifted by noise is not residue). `surface_px`: the local surface
  // is a Gaussian-weighted mean (sigma in pixels) of the soil depths around each pixel; 0
  // keeps the plane. `envelope_px` > 0 starts from the envelope over a window of that
  // side (pixels) instead of the plane.
  SoilSurface(double height_mm, double max_height_mm, double surface_px, double envelope_px);

  // Height above the soil surface in mm, positive towards the camera, of the 3x3 median
  // depth (CV_32FC1): NaN where `missing` or where most of the 3x3 neighbours have no
  // depth, where no pixel within the envelope's window may be soil, and everywhere when no
  // plane could be found. Only pixels marked in `candidates` may support the surface.
  // Returns the height above which this frame's pixels are residue.
  double heights(const cv::Mat& depth_mm, const cv::Mat& missing, const cv::Mat& candidates,
                 cv::Mat& height_mm) const;
  // The same, and in `plane_height_mm` each pixel's height above the plane through the
  // farthest depths (the start without an envelope), which a pile's lowest layer does not
  // reach down to the way the envelope does: NaN where the pixel has no depth, and
  // everywhere when no plane could be found.
  double heights(const cv::Mat& depth_mm, const cv::Mat& missing, const cv::Mat& candidates,
                 cv::Mat& height_mm, cv::Mat& plane_height_mm) const;

 private:
  // `height_mm_`, or 1.7 standard deviations of the 3x3 median depth's noise when that
  // is more, up to `max_height_mm_`.
  double residue_height_mm(const cv::Mat& depth_mm) const;
  double heights(const cv::Mat& depth_mm, const cv::Mat& missing, const cv::Mat& candidates,
                 cv::Mat& height_mm, cv::Mat* plane_height_mm) const;

  const double height_mm_;
  const double max_height_mm_;
  const double surface_px_;
  const cv::Mat envelope_window_;  // empty: start from the plane
};

// The parameters of the stages that use it: `height_mm`, `max_height_mm`, `surface_px`
// and `envelope_px`.
ParamSpec height_mm_param();
ParamSpec max_height_mm_param();
ParamSpec surface_px_param();
ParamSpec envelope_px_param();

}  // namespace tilth::segmentation
