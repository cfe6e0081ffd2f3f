#include "color_range_table.h"

#include <cstring>

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
  hold_as_runs_if_possible();
}

void ColorRangeTable::hold_as_runs_if_possible() {
  std::vector<Run> runs(std::size_t{1} << 16);
  for (std::size_t green_red = 0; green_red < runs.size(); ++green_red) {
    const std::uint8_t* blues = in_range_.get() + (green_red << 8);
    int first = 0;
    while (first < 256 && blues[first] == 0) ++first;
    int last = first;
    while (last + 1 < 256 && blues[last + 1] != 0) ++last;
    for (int b = last + 1; b < 256; ++b) {
      if (blues[b] != 0) return;  // a second run
    }
    runs[green_red] = first < 256
                          ? Run{static_cast<std::uint8_t>(first), static_cast<std::uint8_t>(last)}
                          : Run{1, 0};
  }
  runs_ = std::move(runs);
  in_range_.reset();
}

bool ColorRangeTable::contains(std::uint8_t b, std::uint8_t g, std::uint8_t r) const {
  const std::size_t green_red = g | (std::size_t{r} << 8);
  if (runs_.empty()) return in_range_.get()[b | (green_red << 8)] != 0;
  const Run run = runs_[green_red];
  return b >= run.first && b <= run.last;
}

void ColorRangeTable::classify_row(const std::uint8_t* bgr, int count,
                                   std::uint8_t* in_range) const {
  if (count <= 0) return;
  // Each pixel's three bytes are read as one four-byte word, except the last pixel's,
  // whose fourth byte may lie beyond the image. Through local pointers, the compiler
  // need not reload the table after every byte written.
  if (runs_.empty()) {
    const std::uint8_t* const table = in_range_.get();
    for (int x = 0; x + 1 < count; ++x) {
      std::uint32_t bytes;
      std::memcpy(&bytes, bgr + 3 * x, sizeof bytes);
      in_range[x] = table[bytes & 0xFFFFFF];
    }
  } else {
    const Run* const runs = runs_.data();
    for (int x = 0; x + 1 < count; ++x) {
      std::uint32_t bytes;
      std::memcpy(&bytes, bgr + 3 * x, sizeof bytes);
      const Run run = runs[(bytes >> 8) & 0xFFFF];
      const int blue = static_cast<int>(bytes & 0xFF);
      // One sign test instead of two comparisons, which the compiler would branch on.
      in_range[x] = ((blue - run.first) | (run.last - blue)) >= 0 ? 255 : 0;
    }
  }
  const std::uint8_t* last = bgr + 3 * (count - 1);
  in_range[count - 1] = contains(last[0], last[1], last[2]) ? 255 : 0;
}

}  // namespace tilth::segmentation
