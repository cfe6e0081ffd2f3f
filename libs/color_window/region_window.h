// The window of the colour camera's sensor that registration reads for a region of the
// depth image, with the ground anywhere between two distances: what a commissioned colour
// camera needs to read out (a region of interest: fewer bytes, frames complete sooner).
#pragma once

#include <opencv2/core/types.hpp>

#include "tilth/calibration.h"

namespace tilth {

// The smallest window, its corner and size multiples of `step` px, that holds every
// colour pixel the depth pixels of `depth_region` see, with the neighbours sampling reads
// around it, when the ground lies parallel to the mounting surface between near_mm and
// far_mm from it; clipped to the colour image. Throws tilth::Error when the region sees
// none of the colour image, or its arguments make no window.
cv::Rect color_window_for(const RigCalibration& rig, const cv::Rect& depth_region, double near_mm,
                          double far_mm, int step);

}  // namespace tilth
