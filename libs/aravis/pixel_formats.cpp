#include "pixel_formats.h"

#include <cstdio>

#include <opencv2/core/hal/interface.h>

namespace tilth::aravis {

const std::vector<ImageFormat>& tof_formats() {
  static const std::vector<ImageFormat> formats = {
      {"Mono16", ARV_PIXEL_FORMAT_MONO_16, CV_16UC1, std::nullopt},
      {"Coord3D_C16", ARV_PIXEL_FORMAT_COORD3D_C_16, CV_16UC1, std::nullopt},
  };
  return formats;
}

const std::vector<ImageFormat>& color_formats() {
  static const std::vector<ImageFormat> formats = {
      {"BayerRG8", ARV_PIXEL_FORMAT_BAYER_RG_8, CV_8UC1, PixelFormat::kBayerRggb8},
      {"BayerGR8", ARV_PIXEL_FORMAT_BAYER_GR_8, CV_8UC1, PixelFormat::kBayerGrbg8},
      {"BayerGB8", ARV_PIXEL_FORMAT_BAYER_GB_8, CV_8UC1, PixelFormat::kBayerGbrg8},
      {"BayerBG8", ARV_PIXEL_FORMAT_BAYER_BG_8, CV_8UC1, PixelFormat::kBayerBggr8},
      {"RGB8", ARV_PIXEL_FORMAT_RGB_8_PACKED, CV_8UC3, PixelFormat::kRgb8},
      {"BGR8", ARV_PIXEL_FORMAT_BGR_8_PACKED, CV_8UC3, PixelFormat::kBgr8},
      {"Mono8", ARV_PIXEL_FORMAT_MONO_8, CV_8UC1, PixelFormat::kMono8},
  };
  return formats;
}

const ImageFormat* find_format(const std::vector<ImageFormat>& formats, ArvPixelFormat format) {
  for (const auto& candidate : formats) {
    if (candidate.arv == format) return &candidate;
  }
  return nullptr;
}

std::vector<std::string> format_names(const std::vector<ImageFormat>& formats) {
  std::vector<std::string> names;
  for (const auto& format : formats) names.emplace_back(format.genicam_name);
  return names;
}

std::string describe_pixel_format(ArvPixelFormat format) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%08x", static_cast<unsigned>(format));
  for (const auto* formats : {&tof_formats(), &color_formats()}) {
    if (const ImageFormat* known = find_format(*formats, format)) {
      return std::string(known->genicam_name) + " (" + code + ")";
    }
  }
  return code;
}

}  // namespace tilth::aravis
