#include "mcap/color_window_metadata.h"

#include <array>
#include <charconv>
#include <string>

#include "tilth/error.h"

namespace tilth::mcap {

Metadata color_window_metadata(const cv::Rect& window) {
  return {std::string(kColorWindowMetadata),
          {{"x", std::to_string(window.x)},
           {"y", std::to_string(window.y)},
           {"width", std::to_string(window.width)},
           {"height", std::to_string(window.height)}}};
}

std::optional<cv::Rect> read_color_window(McapReader& reader, const CameraIntrinsics& color) {
  for (const MetadataIndex& index : reader.metadata()) {
    if (index.name != kColorWindowMetadata) continue;
    const Metadata metadata = reader.read_metadata(index);
    const std::string expected = "x, y, width and height in pixels, a window inside the " +
                                 std::to_string(color.width) + "x" + std::to_string(color.height) +
                                 " px colour image of the calibration";
    std::array<int, 4> numbers{};
    const std::array<const char*, 4> names{"x", "y", "width", "height"};
    for (std::size_t i = 0; i < names.size(); ++i) {
      const auto it = metadata.values.find(names[i]);
      const char* end =
          it == metadata.values.end() ? nullptr : it->second.data() + it->second.size();
      if (it == metadata.values.end() ||
          std::from_chars(it->second.data(), end, numbers[i]).ptr != end || numbers[i] < 0) {
        throw Error(reader.file().string() + ": metadata " + std::string(kColorWindowMetadata) +
                    ": expected " + expected);
      }
    }
    const cv::Rect window(numbers[0], numbers[1], numbers[2], numbers[3]);
    if (window.empty() || (window & cv::Rect(0, 0, color.width, color.height)) != window) {
      throw Error(reader.file().string() + ": metadata " + std::string(kColorWindowMetadata) +
                  ": " + window_text(window) + "; expected " + expected);
    }
    return window;
  }
  return std::nullopt;
}

}  // namespace tilth::mcap
