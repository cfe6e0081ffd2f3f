// Raw ToF frame: the 16-bit gray values a time-of-flight camera delivers, before
// depth projection.
#pragma once

#include <cstdint>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct RawTofFrame : MessageOf<RawTofFrame> {
  static constexpr std::string_view kTypeName = "tilth.RawTofFrame";

  cv::Mat gray;                          // CV_16UC1; 0 = no measurement
  std::int64_t device_timestamp_ns = 0;  // capture time on this camera's clock
  // The camera's own gray-to-millimetre scale and offset (GenICam Scan3dCoordinateScale /
  // Scan3dCoordinateOffset) when it reports them; they win over the calibration file.
  std::optional<double> scale_mm;
  std::optional<double> offset_mm;

  std::string summary() const override;
};

}  // namespace tilth
