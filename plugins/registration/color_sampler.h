// Reading a packed colour image (bgr8, rgb8, mono8) as blue, green, red at a pixel
// given by its byte offset in the image. Bayer mosaics are demosaiced to bgr8 first.
#pragma once

#include <cstddef>
#include <cstdint>

#include <opencv2/core/mat.hpp>

namespace tilth::registration {

struct Bgr {
  int b, g, r;
};

// kBlue, kGreen, kRed: each channel's byte within a pixel. The image's address and row
// step are plain members, not read through the cv::Mat, so that the compiler need not
// reload them after every byte the registration writes.
template <int kBlue, int kGreen, int kRed, int kBytesPerPixel>
class PackedSampler {
 public:
  static constexpr int kPixelBytes = kBytesPerPixel;

  explicit PackedSampler(const cv::Mat& image)
      : data_(image.data), step_(static_cast<std::ptrdiff_t>(image.step[0])) {}

  std::ptrdiff_t step() const { return step_; }
  std::ptrdiff_t offset(int x, int y) const { return y * step_ + kBytesPerPixel * x; }
  Bgr at(std::ptrdiff_t offset) const {
    const std::uint8_t* p = data_ + offset;
    return {p[kBlue], p[kGreen], p[kRed]};
  }

 private:
  const std::uint8_t* data_;
  std::ptrdiff_t step_;
};

using BgrSampler = PackedSampler<0, 1, 2, 3>;
using RgbSampler = PackedSampler<2, 1, 0, 3>;
using MonoSampler = PackedSampler<0, 0, 0, 1>;

}  // namespace tilth::registration
