#include "image_folder/png_row_filters.h"

#include <cstdlib>

namespace tilth::recording {
namespace {

std::uint8_t paeth_predictor(int left, int up, int up_left) {
  const int estimate = left + up - up_left;
  const int to_left = std::abs(estimate - left);
  const int to_up = std::abs(estimate - up);
  const int to_up_left = std::abs(estimate - up_left);
  if (to_left <= to_up && to_left <= to_up_left) return static_cast<std::uint8_t>(left);
  return static_cast<std::uint8_t>(to_up <= to_up_left ? up : up_left);
}

}  // namespace

void unfilter_png_row(PngFilter filter, std::uint8_t* row, const std::uint8_t* above,
                      std::size_t length, std::size_t pixel_bytes) {
  const std::size_t first = pixel_bytes < length ? pixel_bytes : length;
  switch (filter) {
    case PngFilter::kNone:
      return;
    case PngFilter::kSub:
      for (std::size_t i = pixel_bytes; i < length; ++i) row[i] += row[i - pixel_bytes];
      return;
    case PngFilter::kUp:
      for (std::size_t i = 0; i < length; ++i) row[i] += above[i];
      return;
    case PngFilter::kAverage:
      for (std::size_t i = 0; i < first; ++i) row[i] += above[i] >> 1;
      for (std::size_t i = pixel_bytes; i < length; ++i) {
        row[i] += static_cast<std::uint8_t>((row[i - pixel_bytes] + above[i]) >> 1);
      }
      return;
    case PngFilter::kPaeth:
      for (std::size_t i = 0; i < first; ++i) row[i] += above[i];
      for (std::size_t i = pixel_bytes; i < length; ++i) {
        row[i] += paeth_predictor(row[i - pixel_bytes], above[i], above[i - pixel_bytes]);
      }
      return;
  }
}

}  // namespace tilth::recording
