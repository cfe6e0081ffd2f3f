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

// A byte per colour and 3 more (ResidueKernels::in_table reads each entry as a word), in
// whole huge pages. Asked for before the first write, which is when the pages are made.
// Where transparent huge pages are off, the advice is ignored and the table has
// ordinary pages.
std::uint8_t* allocate_on_huge_pages() {
  void* bytes = std::aligned_alloc(kHugePage, kColors + kHugePage);
  if (bytes == nullptr) throw std::bad_alloc();
  madvise(bytes, kColors, MADV_HUGEPAGE);
  std::memset(static_cast<std::uint8_t*>(bytes) + kColors, 0, 3);
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
  constexpr BlueRun kNoBlue = 1;  // first 1, last 0
  std::vector<BlueRun> runs((std::size_t{1} << 16) + 1, kNoBlue);
  for (std::size_t green_red = 0; green_red + 1 < runs.size(); ++green_red) {
    const std::uint8_t* blues = in_range_.get() + (green_red << 8);
    int first = 0;
    while (first < 256 && blues[first] == 0) ++first;
    int last = first;
    while (last + 1 < 256 && blues[last + 1] != 0) ++last;
    for (int b = last + 1; b < 256; ++b) {
      if (blues[b] != 0) return;  // a second run
    }
    if (first < 256) runs[green_red] = static_cast<BlueRun>(first | last << 8);
  }
  runs_ = std::move(runs);
  in_range_.reset();
}

bool ColorRangeTable::contains(std::uint8_t b, std::uint8_t g, std::uint8_t r) const {
  const std::size_t green_red = g | (std::size_t{r} << 8);
  if (runs_.empty()) return in_range_.get()[b | (green_red << 8)] != 0;
  const BlueRun run = runs_[green_red];
  return b >= (run & 0xFF) && b <= (run >> 8);
}

void ColorRangeTable::classify_row(const ResidueKernels& kernels, const std::uint8_t* bgr,
                                   int count, std::uint64_t* bits) const {
  if (runs_.empty()) {
    kernels.in_table(in_range_.get(), bgr, count, bits);
  } else {
    kernels.in_runs(runs_.data(), bgr, count, bits);
  }
}

}  // namespace tilth::segmentation
