// Colour resampled onto the depth camera's pixel grid, with a status per pixel saying
// whether its colour can be trusted.
#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct RegisteredColor : MessageOf<RegisteredColor> {
  static constexpr std::string_view kTypeName = "tilth.RegisteredColor";

  enum Status : std::uint8_t {
    kValid = 0,
    kNoDepth = 1,        // the depth pixel has no measurement
    kOutsideColor = 2,   // it projects outside the colour image
    kOccluded = 3,       // the colour camera sees something nearer along that ray
    kNotRegistered = 4,  // outside the rows registered (the stage's region of interest)
  };

  cv::Mat bgr;     // CV_8UC3, depth grid size; black where status != kValid
  cv::Mat status;  // CV_8UC1, Status per pixel

  std::string summary() const override;
};

}  // namespace tilth
