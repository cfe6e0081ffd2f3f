#include "box_sums.h"

#include <cstdint>
#include <cstring>
#include <vector>

#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

constexpr int kMaxRadius = 3;  // 49 * 255 fits in 16 bits

// BORDER_REFLECT: -1 is 0, n is n - 1.
int reflect(int at, int size) {
  if (at < 0) return -at - 1;
  if (at >= size) return 2 * size - at - 1;
  return at;
}

// The `width` sums along one padded row of width + 2r pixels, channel by channel.
template <int kRadius>
void sum_across(const std::uint8_t* padded, int width, std::uint16_t* out) {
  const int values = 3 * width;
  for (int i = 0; i < values; ++i) {
    std::uint16_t sum = 0;
    for (int k = 0; k <= 2 * kRadius; ++k) sum += padded[i + 3 * k];
    out[i] = sum;
  }
}

void sum_across(int radius, const std::uint8_t* padded, int width, std::uint16_t* out) {
  switch (radius) {
    case 0:
      return sum_across<0>(padded, width, out);
    case 1:
      return sum_across<1>(padded, width, out);
    case 2:
      return sum_across<2>(padded, width, out);
    default:
      return sum_across<3>(padded, width, out);
  }
}

}  // namespace

void box_sums(const cv::Mat& bgr, int radius, cv::Mat& summed) {
  if (bgr.type() != CV_8UC3 || radius < 0 || radius > kMaxRadius) {
    throw Error("box_sums: expected a CV_8UC3 image and a radius of 0 to 3, got type " +
                std::to_string(bgr.type()) + " and " + std::to_string(radius));
  }
  cv::Size whole;
  cv::Point offset;
  bgr.locateROI(whole, offset);
  const int width = bgr.cols;
  const int height = bgr.rows;
  const int side = 2 * radius + 1;
  summed.create(bgr.size(), CV_16UC3);
  if (bgr.empty()) return;
  // Where the boxes reach past the image's left or right edge, each row is copied with
  // the image's pixels from `radius` left of the view to `radius` right of it, reflected
  // there: `columns` are their columns in the whole image.
  const bool inside = offset.x - radius >= 0 && offset.x + width + radius <= whole.width;
  thread_local std::vector<int> columns;
  thread_local std::vector<std::uint8_t> padded;
  if (!inside) {
    columns.resize(static_cast<std::size_t>(width + 2 * radius));
    for (int i = 0; i < width + 2 * radius; ++i) {
      columns[static_cast<std::size_t>(i)] = reflect(offset.x - radius + i, whole.width);
    }
    padded.resize(3 * columns.size());
  }
  thread_local std::vector<std::uint16_t> across;  // one row of sums per box row, in a ring
  const std::size_t row_values = static_cast<std::size_t>(3 * width);
  across.resize(static_cast<std::size_t>(side) * row_values);
  // Rows of the whole image from the view's first row.
  const std::uint8_t* const view_row0 = bgr.data;
  const auto image_row = [&](int view_row) {
    const int row = reflect(offset.y + view_row, whole.height) - offset.y;
    return view_row0 + static_cast<std::ptrdiff_t>(row) * static_cast<std::ptrdiff_t>(bgr.step);
  };
  const auto sum_row = [&](int view_row) {
    const std::uint8_t* row = image_row(view_row) - 3 * offset.x;  // column 0 of the image
    const std::uint8_t* source = row + 3 * (offset.x - radius);
    if (!inside) {
      for (std::size_t i = 0; i < columns.size(); ++i) {
        std::memcpy(padded.data() + 3 * i, row + 3 * columns[i], 3);
      }
      source = padded.data();
    }
    std::uint16_t* out =
        across.data() + static_cast<std::size_t>((view_row + side) % side) * row_values;
    sum_across(radius, source, width, out);
  };
  for (int row = -radius; row < radius; ++row) sum_row(row);
  for (int row = 0; row < height; ++row) {
    sum_row(row + radius);
    auto* out = summed.ptr<std::uint16_t>(row);
    const std::uint16_t* first = across.data();
    std::memcpy(out, first, row_values * sizeof(std::uint16_t));
    for (int k = 1; k < side; ++k) {
      const std::uint16_t* next = across.data() + static_cast<std::size_t>(k) * row_values;
      for (std::size_t i = 0; i < row_values; ++i) out[i] += next[i];
    }
  }
}

}  // namespace tilth::segmentation
