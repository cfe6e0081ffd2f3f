// The test images of Aravis's camera simulator, to tell a frame passed on whole from one
// with missing or stale rows. At the simulator's default exposure and gain, pixel (x, y)
// of block id b is (x + y + b) mod 255 in Mono8 and ((x + y + b) * 256) mod 65535 in
// Mono16 (both hold across the 16-bit block id wrap, since 65535 is a multiple of 255).
// Whatever the exposure and gain, and in the colour formats (a colour ramp), the image
// is constant along anti-diagonals: unchanged by (x, y) -> (x + 1, y - 1), or by
// (x + 2, y - 2) in a Bayer mosaic.
#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

namespace tilth::testing {

inline bool matches_fake_mono8(const cv::Mat& image, std::uint64_t block_id) {
  if (image.type() != CV_8UC1 || image.empty()) return false;
  for (int y = 0; y < image.rows; ++y) {
    const auto* row = image.ptr<std::uint8_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      if (row[x] != (static_cast<std::uint64_t>(x + y) + block_id) % 255) return false;
    }
  }
  return true;
}

inline bool matches_fake_mono16(const cv::Mat& image, std::uint64_t block_id) {
  if (image.type() != CV_16UC1 || image.empty()) return false;
  for (int y = 0; y < image.rows; ++y) {
    const auto* row = image.ptr<std::uint16_t>(y);
    for (int x = 0; x < image.cols; ++x) {
      if (row[x] != ((static_cast<std::uint64_t>(x + y) + block_id) * 256) % 65535) return false;
    }
  }
  return true;
}

template <class Pixel>
bool constant_along_antidiagonals(const cv::Mat& image, int step) {
  if (image.elemSize() != sizeof(Pixel) || image.rows <= step || image.cols <= step) return false;
  for (int y = step; y < image.rows; ++y) {
    const auto* row = image.ptr<Pixel>(y);
    const auto* above = image.ptr<Pixel>(y - step);
    for (int x = 0; x + step < image.cols; ++x) {
      if (above[x + step] != row[x]) return false;
    }
  }
  return true;
}

inline bool matches_fake_bayer(const cv::Mat& mosaic) {
  return mosaic.type() == CV_8UC1 && constant_along_antidiagonals<std::uint8_t>(mosaic, 2);
}

}  // namespace tilth::testing
