// Reading a colour image as blue, green, red near a point of it. A sampler reads the
// `span` x `span` pixels nearest the point, found by its pixel key (Addressing): packed
// images (bgr8, rgb8, mono8) one pixel, Bayer mosaics the 2x2 quad of one red, two greens
// and one blue, which demosaics at the point only.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <opencv2/core/mat.hpp>

namespace tilth::registration {

struct Bgr {
  int b, g, r;
};

// Which pixels a sampler reads for a point (u, v) (0-based, (0,0) at the centre of the
// top-left pixel), as computed for many points at once by the registration: the
// top-left one, x = clamp(floor(u + (1 - span) / 2 + 0.5), 0, width - span) and likewise
// y, identified by the key y * row_key + x * column_key + (y & 1) * odd_row +
// (x & 1) * odd_column.
struct Addressing {
  int span;
  int row_key;
  int column_key;
  int odd_row;
  int odd_column;
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

// A Bayer mosaic read at a 2x2 quad: its red, its blue and the mean of its greens. The
// quad may start on any pixel, so each of the four phases (x and y odd or even) has its
// own layout; the key is 4 * the quad's byte offset + its phase.
class BayerQuadSampler {
 public:
  // `tile`: the mosaic's top-left 2x2 tile row by row, e.g. "RGGB".
  BayerQuadSampler(const cv::Mat& mosaic, std::string_view tile)
      : data_(mosaic.data), step_(static_cast<std::ptrdiff_t>(mosaic.step[0])) {
    for (int phase = 0; phase < 4; ++phase) {
      int green = 0;
      for (int dy = 0; dy < 2; ++dy) {
        for (int dx = 0; dx < 2; ++dx) {
          const auto site = static_cast<std::size_t>(((phase / 2 + dy) % 2) * 2 + (phase + dx) % 2);
          const std::ptrdiff_t offset = dy * step_ + dx;
          auto& layout = layouts_[static_cast<std::size_t>(phase)];
          if (tile[site] == 'R') {
            layout.red = offset;
          } else if (tile[site] == 'B') {
            layout.blue = offset;
          } else {
            layout.greens[static_cast<std::size_t>(green++)] = offset;
          }
        }
      }
    }
  }

  Addressing addressing() const { return {2, 4 * static_cast<int>(step_), 4, 2, 1}; }
  Bgr at(std::ptrdiff_t key) const {
    const Layout& layout = layouts_[static_cast<std::size_t>(key & 3)];
    const std::uint8_t* quad = data_ + (key >> 2);
    return {quad[layout.blue], (quad[layout.greens[0]] + quad[layout.greens[1]] + 1) >> 1,
            quad[layout.red]};
  }

 private:
  struct Layout {
    std::ptrdiff_t red = 0, blue = 0;
    std::array<std::ptrdiff_t, 2> greens{};
  };

  const std::uint8_t* data_;
  std::ptrdiff_t step_;
  std::array<Layout, 4> layouts_{};
};

}  // namespace tilth::registration
