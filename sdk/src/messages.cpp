// Summaries and names of the shared message types.
#include <array>
#include <cmath>
#include <sstream>
#include <utility>

#include <opencv2/core.hpp>

#include "tilth/messages/camera_status.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/ground_distance.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/pipeline_metrics.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"

namespace tilth {
namespace {

constexpr std::array<std::pair<PixelFormat, std::string_view>, 7> kPixelFormatNames{{
    {PixelFormat::kBgr8, "bgr8"},
    {PixelFormat::kRgb8, "rgb8"},
    {PixelFormat::kMono8, "mono8"},
    {PixelFormat::kBayerRggb8, "bayer_rggb8"},
    {PixelFormat::kBayerBggr8, "bayer_bggr8"},
    {PixelFormat::kBayerGrbg8, "bayer_grbg8"},
    {PixelFormat::kBayerGbrg8, "bayer_gbrg8"},
}};

std::string size_of(const cv::Mat& image) {
  return std::to_string(image.cols) + "x" + std::to_string(image.rows);
}

}  // namespace

std::string_view to_string(PixelFormat format) {
  for (const auto& [value, name] : kPixelFormatNames) {
    if (value == format) return name;
  }
  return "unknown";
}

std::optional<PixelFormat> parse_pixel_format(std::string_view name) {
  for (const auto& [value, known] : kPixelFormatNames) {
    if (known == name) return value;
  }
  return std::nullopt;
}

int channels(PixelFormat format) {
  return format == PixelFormat::kBgr8 || format == PixelFormat::kRgb8 ? 3 : 1;
}

std::string CameraStatus::summary() const {
  std::ostringstream out;
  out << camera << (streaming ? " streaming" : " not streaming");
  if (!problem.empty()) out << " (" << problem << ")";
  out << ", " << completed << " complete, " << incomplete << " incomplete, " << lost << " lost, "
      << late << " late";
  return out.str();
}

std::string RawTofFrame::summary() const { return "raw ToF " + size_of(gray); }

std::string DepthImage::summary() const {
  int valid = 0;
  double sum = 0.0;
  for (int r = 0; r < mm.rows; ++r) {
    const float* row = mm.ptr<float>(r);
    for (int c = 0; c < mm.cols; ++c) {
      if (std::isfinite(row[c])) {
        ++valid;
        sum += row[c];
      }
    }
  }
  std::ostringstream out;
  out << "depth " << size_of(mm) << ", " << valid << " valid px";
  if (valid > 0) out << ", mean " << sum / valid << " mm";
  return out.str();
}

std::string ColorImage::summary() const {
  std::string text = "colour " + size_of(pixels) + " " + std::string(to_string(format));
  if (sensor_offset) {
    text += " at (" + std::to_string(sensor_offset->x) + ", " + std::to_string(sensor_offset->y) +
            ") on the sensor";
  }
  return text;
}

std::string RegisteredColor::summary() const {
  const int valid = status.empty() ? 0 : cv::countNonZero(status == kValid);
  return "registered colour " + size_of(bgr) + ", " + std::to_string(valid) + " valid px";
}

std::string ResidueMask::summary() const {
  const int total = values.rows * values.cols;
  const int residue = total == 0 ? 0 : cv::countNonZero(values == kResidue);
  return "mask " + size_of(values) + ", " + std::to_string(residue) + " residue px";
}

std::string_view to_string(InvalidCause cause) {
  switch (cause) {
    case InvalidCause::kNone:
      return "none";
    case InvalidCause::kTooLittleSoil:
      return "too_little_soil";
    case InvalidCause::kNotOneSurface:
      return "not_one_surface";
    case InvalidCause::kOutOfRange:
      return "out_of_range";
    case InvalidCause::kLowConfidence:
      return "low_confidence";
    case InvalidCause::kImageUnusable:
      return "image_unusable";
  }
  return "unknown";
}

void GroundDistance::invalidate(InvalidCause why, std::string reason) {
  valid = false;
  cause = why;
  invalid_reason = std::move(reason);
  distance_mm = 0.0;
  confidence = 0.0;
  held = false;
  held_ms = 0.0;
}

std::string GroundDistance::summary() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  if (valid) {
    out << distance_mm << " mm";
    if (held) out << " (held, " << held_ms << " ms old)";
  } else {
    out << "invalid (" << invalid_reason << ")";
  }
  out << ", soil " << soil_fraction * 100.0 << " %, confidence " << confidence;
  return out.str();
}

std::string GroundTruth::summary() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  out << "truth ";
  if (distance_mm) {
    out << *distance_mm << " mm";
  } else {
    out << "distance unknown";
  }
  if (!residue_mask.empty()) out << ", mask " << size_of(residue_mask);
  return out.str();
}

std::string PipelineMetrics::summary() const {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(1);
  out << frames_completed << " frames, " << frames_per_second << " fps, " << frames_dropped
      << " dropped, end-to-end p50 " << end_to_end.p50_ms << " ms";
  return out.str();
}

}  // namespace tilth
