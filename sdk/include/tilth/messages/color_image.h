// Colour image with the pixel format it is stored in (packed or Bayer mosaic).
#pragma once

#include <cstdint>
#include <optional>
#include <string_view>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>

#include "tilth/message.h"

namespace tilth {

enum class PixelFormat { kBgr8, kRgb8, kMono8, kBayerRggb8, kBayerBggr8, kBayerGrbg8, kBayerGbrg8 };

// Names as in the recording format: "bgr8", "bayer_rggb8", ...
std::string_view to_string(PixelFormat format);
std::optional<PixelFormat> parse_pixel_format(std::string_view name);
int channels(PixelFormat format);

struct ColorImage : MessageOf<ColorImage> {
  static constexpr std::string_view kTypeName = "tilth.ColorImage";

  cv::Mat pixels;  // CV_8UC3 for bgr8/rgb8, CV_8UC1 for mono8 and Bayer
  PixelFormat format = PixelFormat::kBgr8;
  std::int64_t device_timestamp_ns = 0;  // capture time on this camera's clock
  // Set by a camera that says where the image lies on its sensor: the sensor pixel of the
  // image's top-left one. With a region of interest (GenICam OffsetX, OffsetY, Width,
  // Height) the image is that window of the calibrated image (with_color_window). Unset:
  // the image is the calibrated image whole.
  std::optional<cv::Point> sensor_offset;

  // The sensor pixels the image holds: at sensor_offset, or at (0, 0) when unset.
  cv::Rect sensor_window() const { return {sensor_offset.value_or(cv::Point()), pixels.size()}; }

  std::string summary() const override;
};

}  // namespace tilth
