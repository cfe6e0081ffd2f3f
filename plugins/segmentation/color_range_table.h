// Which of the 2^24 BGR colours lie in a box of another colour space, one byte each
// (16 MB): built once per parameter set with OpenCV's own conversion and in-range test, so
// a lookup gives exactly what cv::cvtColor + cv::inRange would, for one load per pixel.
// (A bit per colour, 2 MB, costs three more instructions per pixel to find the bit, and
// the lookup is what the segmentation's time goes to; the colours of a frame touch a few
// hundred KB of the table, but on a thousand or more 4 KB pages, too many for the TLB:
// the table asks for 2 MB pages.)
#pragma once

#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>

namespace tilth::segmentation {

class ColorRangeTable {
 public:
  // `conversion`: the cv::ColorConversionCodes from BGR into the box's space, or -1 when
  // the box is in BGR itself. `lower`, `upper`: inclusive 8-bit bounds per channel.
  ColorRangeTable(int conversion, const std::array<int, 3>& lower, const std::array<int, 3>& upper);

  // `bgr24`: blue in bits 0-7, green 8-15, red 16-23 (a BGR pixel's bytes read little-endian).
  // 255 inside the box, 0 outside, as cv::inRange writes.
  std::uint8_t in_range(std::uint32_t bgr24) const { return in_range_.get()[bgr24]; }
  // The 2^24 bytes themselves, for loops that write bytes: through a pointer held in a
  // local, the compiler need not reload it after every byte written.
  const std::uint8_t* data() const { return in_range_.get(); }
  bool contains(std::uint8_t b, std::uint8_t g, std::uint8_t r) const {
    return in_range(b | (std::uint32_t{g} << 8) | (std::uint32_t{r} << 16)) != 0;
  }

 private:
  struct Free {
    void operator()(std::uint8_t* bytes) const { std::free(bytes); }
  };
  std::unique_ptr<std::uint8_t[], Free> in_range_;
};

}  // namespace tilth::segmentation
