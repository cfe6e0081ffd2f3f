// Fuzz target: a frame's PNG through decode_png(), and through OpenCV beside it. Damage
// must end in tilth::Error; a crash, a sanitizer report, any other exception, or pixels
// that differ from OpenCV's when both decode the file is a bug.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "image_folder/png_decoder.h"
#include "tilth/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::optional<cv::Mat> decoded;
  try {
    decoded = tilth::recording::decode_png(
        std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.png");
  } catch (const tilth::Error&) {
    return 0;
  }
  if (!decoded || size == 0) return 0;
  const cv::Mat opencv =
      cv::imdecode(cv::Mat(1, static_cast<int>(size), CV_8UC1, const_cast<std::uint8_t*>(data)),
                   cv::IMREAD_UNCHANGED);
  if (opencv.empty()) return 0;  // OpenCV refuses more (libpng's limits), not a fault here
  if (opencv.type() != decoded->type() || opencv.size() != decoded->size() ||
      cv::norm(opencv, *decoded, cv::NORM_INF) != 0.0) {
    std::abort();
  }
  return 0;
}
