#include "labelled_mask.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <unordered_map>

#include <opencv2/imgproc.hpp>

#include "image_folder/image_file.h"
#include "image_folder/pixel_checks.h"
#include "png_palette.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::tools {
namespace {

namespace fs = std::filesystem;

std::uint32_t key(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  return std::uint32_t{r} << 16 | std::uint32_t{g} << 8 | b;
}

std::string rgb_text(std::uint32_t rgb) {
  return std::to_string(rgb >> 16) + "," + std::to_string(rgb >> 8 & 0xff) + "," +
         std::to_string(rgb & 0xff);
}

// The first pixel nothing maps, and how many there are.
struct Unmapped {
  std::optional<cv::Point> first;
  std::uint32_t value = 0;  // its colour (r, g, b packed) or index
  std::size_t count = 0;

  void add(int x, int y, std::uint32_t what) {
    if (count++ == 0) {
      first = cv::Point(x, y);
      value = what;
    }
  }
};

// Classes by colour: `by_color` maps r, g, b to a mask value.
cv::Mat classes_by_color(const cv::Mat& bgr,
                         const std::unordered_map<std::uint32_t, std::uint8_t>& by_color,
                         Unmapped& unmapped) {
  cv::Mat classes(bgr.size(), CV_8UC1);
  for (int y = 0; y < bgr.rows; ++y) {
    const auto* pixel = bgr.ptr<cv::Vec3b>(y);
    auto* out = classes.ptr<std::uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      const std::uint32_t rgb = key(pixel[x][2], pixel[x][1], pixel[x][0]);
      const auto found = by_color.find(rgb);
      if (found == by_color.end()) {
        unmapped.add(x, y, rgb);
        out[x] = 0;
      } else {
        out[x] = found->second;
      }
    }
  }
  return classes;
}

// A colour PNG as 3-channel BGR: a grey level g is g,g,g and alpha is dropped.
cv::Mat as_bgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  if (image.channels() == 3) bgr = image;
  if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  return bgr;
}

std::string labelled_by(const LabelMap& map) { return map.file.filename().string(); }

// labelme2voc writes its __ignore__ label as index -1, which an 8-bit PNG stores as 255.
constexpr std::size_t kIgnoredIndex = 255;

using IndexValues = std::array<std::optional<std::uint8_t>, 256>;

cv::Mat classes_by_index(const cv::Mat& indices, const IndexValues& by_index, Unmapped& unmapped) {
  cv::Mat classes(indices.size(), CV_8UC1);
  for (int y = 0; y < indices.rows; ++y) {
    const auto* index = indices.ptr<std::uint8_t>(y);
    auto* out = classes.ptr<std::uint8_t>(y);
    for (int x = 0; x < indices.cols; ++x) {
      const auto& value = by_index[index[x]];
      if (!value) unmapped.add(x, y, index[x]);
      out[x] = value.value_or(0);
    }
  }
  return classes;
}

// The colours a palette PNG gives the indices that have a value. Throws tilth::Error when
// the file has no palette, or two of those indices share a colour.
std::unordered_map<std::uint32_t, std::uint8_t> palette_colors(const fs::path& file,
                                                               const std::string& bytes,
                                                               const IndexValues& by_index) {
  const std::vector<cv::Vec3b> palette = png_palette(bytes);
  if (palette.empty()) {
    throw Error(file.string() +
                ": is a colour image without a palette; expected class indices (LabelMe): a "
                "palette or grey PNG");
  }
  std::unordered_map<std::uint32_t, std::uint8_t> by_color;
  std::unordered_map<std::uint32_t, std::size_t> index_of;
  for (std::size_t i = 0; i < std::min(palette.size(), by_index.size()); ++i) {
    if (!by_index[i]) continue;
    const std::uint32_t rgb = key(palette[i][0], palette[i][1], palette[i][2]);
    if (const auto twice = index_of.find(rgb); twice != index_of.end()) {
      throw Error(file.string() + ": palette entries " + std::to_string(twice->second) + " and " +
                  std::to_string(i) + " have the same colour " + rgb_text(rgb) +
                  "; expected a colour per class index");
    }
    index_of[rgb] = i;
    by_color[rgb] = *by_index[i];
  }
  return by_color;
}

}  // namespace

cv::Mat read_labelled_mask(const fs::path& file, const LabelMap& map, cv::Size size,
                           const std::string& size_origin) {
  const std::string bytes = recording::read_image_bytes(file);
  const cv::Mat image = recording::decode_image(bytes, file);
  if (image.depth() != CV_8U || image.size() != size) {
    throw Error(file.string() + ": expected an 8-bit mask of " + std::to_string(size.width) + "x" +
                std::to_string(size.height) + " pixels (" + size_origin + "), got " +
                recording::describe_pixels(image.type(), image.size()));
  }
  Unmapped unmapped;
  cv::Mat classes;
  std::string unmapped_text;
  if (map.encoding == LabelMap::Encoding::kColor) {
    std::unordered_map<std::uint32_t, std::uint8_t> by_color;
    for (const Label& label : map.labels) {
      by_color[key((*label.rgb)[0], (*label.rgb)[1], (*label.rgb)[2])] = label.mask_value;
    }
    classes = classes_by_color(as_bgr(image), by_color, unmapped);
    unmapped_text = "colour " + rgb_text(unmapped.value) + ", which " + labelled_by(map) +
                    " gives no label (labels: " + map.names() + ")";
  } else {
    // Each index's value: its label's, and 255 unknown (labelme2voc's __ignore__).
    IndexValues by_index;
    for (std::size_t i = 0; i < map.labels.size(); ++i) by_index[i] = map.labels[i].mask_value;
    std::string indices = "indices 0 to " + std::to_string(map.labels.size() - 1) +
                          " of the labels in " + labelled_by(map);
    if (!by_index[kIgnoredIndex]) {
      by_index[kIgnoredIndex] = ResidueMask::kUnknown;
      indices += ", and " + std::to_string(kIgnoredIndex) + " for unknown";
    }
    if (image.channels() == 1) {
      classes = classes_by_index(image, by_index, unmapped);
      unmapped_text =
          "class index " + std::to_string(unmapped.value) + " (expected " + indices + ")";
    } else {
      classes = classes_by_color(as_bgr(image), palette_colors(file, bytes, by_index), unmapped);
      unmapped_text = "colour " + rgb_text(unmapped.value) +
                      ", which is no palette entry of the class " + indices;
    }
  }
  if (unmapped.count > 0) {
    throw Error(file.string() + ": pixel (" + std::to_string(unmapped.first->x) + ", " +
                std::to_string(unmapped.first->y) + ") has " + unmapped_text + "; " +
                std::to_string(unmapped.count) +
                " pixels in all have no label (expected the masks and the label names of one "
                "export)");
  }
  return classes;
}

}  // namespace tilth::tools
