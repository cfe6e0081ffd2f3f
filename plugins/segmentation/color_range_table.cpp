#include "color_range_table.h"

#include <sys/mman.h>

#include <new>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace tilth::segmentation {
namespace {

constexpr std::size_t kColors = std::size_t{1} << 24;
constexpr std::size_t kHugePage = std::size_t{2} << 20;

// Asked for before the first write, which is when the pages are made. Where transparent
// huge pages are off, the advice is ignored and the table has ordinary pages.
std::uint8_t* allocate_on_huge_pages() {
  void* bytes = std::aligned_alloc(kHugePage, kColors);
  if (bytes == nullptr) throw std::bad_alloc();
  madvise(bytes, kColors, MADV_HUGEPAGE);
  return static_cast<std::uint8_t*>(bytes);
}

}  // namespace

ColorRangeTable::ColorRangeTable(int conversion, const std::array<int, 3>& lower,
                                 const std::array<int, 3>& upper)
    : in_range_(allocate_on_huge_pages()) {
  // One red value at a time: a 256x256 image of every (blue, green), blue along a row,
  // so that pixel (g, b) is colour b + 256 g + 65536 r, and the in-range result for that
  // red value is the table's 2^16 bytes from 65536 r on.
  cv::Mat colors(256, 256, CV_8UC3);
  for (int g = 0; g < 256; ++g) {
    auto* pixel = colors.ptr<cv::Vec3b>(g);
    for (int b = 0; b < 256; ++b) pixel[b] = cv::Vec3b(b, g, 0);
  }
  cv::Mat converted;
  const cv::Scalar low(lower[0], lower[1], lower[2]);
  const cv::Scalar high(upper[0], upper[1], upper[2]);
  for (int r = 0; r < 256; ++r) {
    auto* pixels = colors.ptr<std::uint8_t>();
    for (int i = 0; i < 256 * 256; ++i) pixels[3 * i + 2] = static_cast<std::uint8_t>(r);
    if (conversion >= 0) {
      cv::cvtColor(colors, converted, conversion);
    } else {
      converted = colors;
    }
    cv::Mat in_range(256, 256, CV_8UC1, in_range_.get() + (static_cast<std::size_t>(r) << 16));
    cv::inRange(converted, low, high, in_range);
  }
}

}  // namespace tilth::segmentation
