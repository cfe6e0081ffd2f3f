#include "png_palette.h"

#include <cstdint>
#include <string_view>

namespace tilth::tools {
namespace {

constexpr std::string_view kSignature("\x89PNG\r\n\x1a\n", 8);

std::uint32_t big_endian(std::string_view bytes) {
  std::uint32_t value = 0;
  for (char byte : bytes.substr(0, 4)) value = value << 8 | static_cast<std::uint8_t>(byte);
  return value;
}

}  // namespace

std::vector<cv::Vec3b> png_palette(const std::string& png) {
  std::string_view rest(png);
  if (!rest.starts_with(kSignature)) return {};
  rest.remove_prefix(kSignature.size());
  // Each chunk: length (4 bytes), type (4), data (length), CRC (4).
  while (rest.size() >= 12) {
    const std::uint32_t length = big_endian(rest);
    const std::string_view type = rest.substr(4, 4);
    if (length > rest.size() - 12) return {};
    if (type == "IDAT" || type == "IEND") return {};
    // A truecolour PNG may carry a suggested palette, which its pixels do not index.
    constexpr std::size_t kColorTypeOffset = 8 + 9;
    constexpr char kPaletteColorType = 3;
    if (type == "IHDR" && (length < 13 || rest[kColorTypeOffset] != kPaletteColorType)) return {};
    if (type == "PLTE") {
      const std::string_view data = rest.substr(8, length);
      std::vector<cv::Vec3b> entries;
      for (std::size_t i = 0; i + 3 <= data.size(); i += 3) {
        entries.emplace_back(static_cast<std::uint8_t>(data[i]),
                             static_cast<std::uint8_t>(data[i + 1]),
                             static_cast<std::uint8_t>(data[i + 2]));
      }
      return entries;
    }
    rest.remove_prefix(12 + static_cast<std::size_t>(length));
  }
  return {};
}

}  // namespace tilth::tools
