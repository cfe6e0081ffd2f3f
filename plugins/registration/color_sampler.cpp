#include "color_sampler.h"

#include <string>
#include <string_view>

#include "tilth/error.h"

namespace tilth::registration {
namespace {

// A mosaic's sites are its top-left 2x2 tile row by row, e.g. "RGGB".
std::array<int, 4> tile_sites(std::string_view tile) {
  std::array<int, 4> sites{};  // blue, green, green, red
  int green = 1;
  for (int site = 0; site < 4; ++site) {
    const char channel = tile[static_cast<std::size_t>(site)];
    sites[static_cast<std::size_t>(channel == 'B' ? 0 : channel == 'R' ? 3 : green++)] = site;
  }
  return sites;
}

}  // namespace

NearestPixels nearest_pixels(const cv::Mat& image, PixelFormat format) {
  const auto step = static_cast<std::ptrdiff_t>(image.step[0]);
  const std::ptrdiff_t size =
      (image.rows - 1) * step + image.cols * static_cast<std::ptrdiff_t>(image.elemSize());
  if (image.empty() || size < 4) {
    throw Error("colour image of " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                " px is too small; at least 4 bytes expected");
  }
  const auto packed = [&](int bytes_per_pixel, std::array<int, 4> sites) {
    return NearestPixels{{1, static_cast<int>(step), bytes_per_pixel, 0, 0},
                         {image.data, size, 0, 0, 0, sites}};
  };
  // A quad's key is 4 * its byte offset + its phase: (y & 1) * 2 + (x & 1).
  const auto quads = [&](std::string_view tile) {
    return NearestPixels{{2, 4 * static_cast<int>(step), 4, 2, 1},
                         {image.data, size, 2, 3, step, tile_sites(tile)}};
  };
  switch (format) {
    case PixelFormat::kBgr8:
      return packed(3, {0, 1, 1, 2});
    case PixelFormat::kRgb8:
      return packed(3, {2, 1, 1, 0});
    case PixelFormat::kMono8:
      return packed(1, {0, 0, 0, 0});
    case PixelFormat::kBayerRggb8:
      return quads("RGGB");
    case PixelFormat::kBayerBggr8:
      return quads("BGGR");
    case PixelFormat::kBayerGrbg8:
      return quads("GRBG");
    case PixelFormat::kBayerGbrg8:
      return quads("GBRG");
  }
  throw Error("unknown colour pixel format");
}

}  // namespace tilth::registration
