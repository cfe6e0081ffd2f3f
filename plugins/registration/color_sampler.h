// Reading a packed colour image (bgr8, rgb8, mono8) at a pixel given by its index
// y * width + x in a continuous image, as blue | green << 8 | red << 16: the three bytes
// of a bgr8 pixel as they lie in memory, so that registration copies a colour with one
// four-byte load and store. Bayer mosaics are demosaiced to bgr8 first.
#pragma once

#include <cstdint>
#include <cstring>

#include <opencv2/core/mat.hpp>

namespace tilth::registration {

// kBlue, kGreen, kRed: each channel's byte within a pixel. The image's address is a plain
// member, not read through the cv::Mat, so that the compiler need not reload it after
// every byte the registration writes.
template <int kBlue, int kGreen, int kRed, int kBytesPerPixel>
class PackedSampler {
 public:
  // `image` must be continuous.
  explicit PackedSampler(const cv::Mat& image)
      : data_(image.data), width_(image.cols), last_(static_cast<int>(image.total()) - 1) {}

  int width() const { return width_; }

  std::uint32_t at(int index) const {
    const std::uint8_t* p = data_ + kBytesPerPixel * static_cast<std::ptrdiff_t>(index);
    if constexpr (kBytesPerPixel == 3 && kBlue == 0 && kGreen == 1 && kRed == 2) {
      // The fourth byte, the next pixel's blue, is masked off; the image's last pixel has
      // none.
      if (index < last_) {
        std::uint32_t bytes;
        std::memcpy(&bytes, p, sizeof bytes);
        return bytes & 0xFFFFFF;
      }
    }
    return p[kBlue] | (std::uint32_t{p[kGreen]} << 8) | (std::uint32_t{p[kRed]} << 16);
  }

 private:
  const std::uint8_t* data_;
  int width_;
  int last_;
};

using BgrSampler = PackedSampler<0, 1, 2, 3>;
using RgbSampler = PackedSampler<2, 1, 0, 3>;
using MonoSampler = PackedSampler<0, 0, 0, 1>;

}  // namespace tilth::registration
