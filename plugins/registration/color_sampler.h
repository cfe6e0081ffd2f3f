// Reading a colour image as blue, green, red near a point of it: a packed image's pixels
// one by one for bilinear sampling, and any image's nearest pixels for the vector loops.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <opencv2/core/mat.hpp>

#include "pixel_word.h"
#include "tilth/messages/color_image.h"

namespace tilth::registration {

struct Bgr {
  int b, g, r;
};

// kBlue, kGreen, kRed: each channel's byte within a pixel. The image's address and row
// step are plain members, not read through the cv::Mat, so that the compiler need not
// reload them after every byte the registration writes. The key is the pixel's byte
// offset.
template <int kBlue, int kGreen, int kRed, int kBytesPerPixel>
class PackedSampler {
 public:
  static constexpr int kPixelBytes = kBytesPerPixel;

  explicit PackedSampler(const cv::Mat& image)
      : data_(image.data), step_(static_cast<std::ptrdiff_t>(image.step[0])) {}

  Addressing addressing() const { return {1, static_cast<int>(step_), kBytesPerPixel, 0, 0}; }
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

// Nearest sampling of `image` in `format`: a packed image's pixel, or a Bayer mosaic's
// 2x2 quad of one red, two greens and one blue, which demosaics at the point only.
// Throws tilth::Error for an image too small to read as words.
NearestPixels nearest_pixels(const cv::Mat& image, PixelFormat format);

}  // namespace tilth::registration
