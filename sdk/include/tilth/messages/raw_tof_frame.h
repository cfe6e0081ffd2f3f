// Raw ToF frame: the 16-bit gray values a time-of-flight camera delivers, before
// depth projection.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "tilth/message.h"

namespace tilth {

struct RigCalibration;

struct RawTofFrame : MessageOf<RawTofFrame> {
  static constexpr std::string_view kTypeName = "tilth.RawTofFrame";

  cv::Mat gray;                          // CV_16UC1; 0 = no measurement
  std::int64_t device_timestamp_ns = 0;  // capture time on this camera's clock
  // The camera's own gray-to-millimetre scale and offset (GenICam Scan3dCoordinateScale /
  // Scan3dCoordinateOffset) when it reports them; they win over the calibration file.
  std::optional<double> scale_mm;
  std::optional<double> offset_mm;
  // The calibration of the rig that captured the frame, when its source knows it (a
  // recording's own, the simulator's, a camera source given one): tilth/frame_calibration.h.
  std::shared_ptr<const RigCalibration> rig;

  std::string summary() const override;
};

}  // namespace tilth
