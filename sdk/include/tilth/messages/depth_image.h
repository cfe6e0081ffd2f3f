// Depth image: distance in millimetres from the mounting surface along the optical
// axis, per ToF pixel.
#pragma once

#include <memory>

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct RigCalibration;

struct DepthImage : MessageOf<DepthImage> {
  static constexpr std::string_view kTypeName = "tilth.DepthImage";

  cv::Mat mm;  // CV_32FC1; NaN = no depth
  // The calibration the depth was computed with (tilth/frame_calibration.h); null when
  // its maker did not say.
  std::shared_ptr<const RigCalibration> rig;

  std::string summary() const override;
};

}  // namespace tilth
