// Depth image: distance in millimetres from the mounting surface along the optical
// axis, per ToF pixel.
#pragma once

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct DepthImage : MessageOf<DepthImage> {
  static constexpr std::string_view kTypeName = "tilth.DepthImage";

  cv::Mat mm;  // CV_32FC1; NaN = no depth

  std::string summary() const override;
};

}  // namespace tilth
