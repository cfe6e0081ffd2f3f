// ColorRangeTable against OpenCV's conversion and in-range test, on every one of the 2^24
// BGR colours: the table must say exactly what cv::cvtColor + cv::inRange say, at every
// instruction-set level this CPU runs.
#include "color_range_table.h"

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace tilth::segmentation {
namespace {

struct Box {
  std::string name;
  int conversion;  // -1: the box is in BGR
  std::array<int, 3> lower;
  std::array<int, 3> upper;
  bool held_as_runs;  // one run of blues for every green and red
};

class EachBox : public ::testing::TestWithParam<Box> {};

TEST_P(EachBox, AgreesWithCvtColorAndInRangeOnEveryColour) {
  const Box& box = GetParam();
  const ColorRangeTable table(box.conversion, box.lower, box.upper);

  // 4096x4096 pixels, each colour once: red from the tile, blue and green within it.
  cv::Mat colors(4096, 4096, CV_8UC3);
  for (int y = 0; y < colors.rows; ++y) {
    auto* pixel = colors.ptr<cv::Vec3b>(y);
    for (int x = 0; x < colors.cols; ++x) {
      pixel[x] = cv::Vec3b(x % 256, y % 256, (y / 256) * 16 + x / 256);
    }
  }
  cv::Mat converted;  // not sharing colors' pixels: cvtColor would write into them
  if (box.conversion >= 0) {
    cv::cvtColor(colors, converted, box.conversion);
  } else {
    converted = colors;
  }
  cv::Mat expected;
  cv::inRange(converted, cv::Scalar(box.lower[0], box.lower[1], box.lower[2]),
              cv::Scalar(box.upper[0], box.upper[1], box.upper[2]), expected);

  int mismatches = 0;
  int inside = 0;
  for (int y = 0; y < colors.rows; ++y) {
    const auto* pixel = colors.ptr<cv::Vec3b>(y);
    const auto* in_range = expected.ptr<std::uint8_t>(y);
    for (int x = 0; x < colors.cols; ++x) {
      const bool contained = table.contains(pixel[x][0], pixel[x][1], pixel[x][2]);
      mismatches += contained != (in_range[x] != 0) ? 1 : 0;
      inside += contained ? 1 : 0;
    }
  }
  EXPECT_EQ(mismatches, 0);
  // A row at a time, as the stage reads a frame, with every level's kernels: whole rows,
  // and rows of 4091 pixels, whose last word and last vectors are partial.
  for (const ResidueKernels* kernels : available_residue_kernels()) {
    for (const int cols : {colors.cols, colors.cols - 5}) {
      int row_mismatches = 0;
      std::vector<std::uint64_t> bits((cols + 63) / 64, ~std::uint64_t{0});
      for (int y = 0; y < colors.rows; ++y) {
        table.classify_row(*kernels, colors.ptr<std::uint8_t>(y), cols, bits.data());
        const auto* in_range = expected.ptr<std::uint8_t>(y);
        for (int x = 0; x < cols; ++x) {
          const bool bit = (bits[x / 64] >> (x % 64)) & 1;
          row_mismatches += bit != (in_range[x] != 0) ? 1 : 0;
        }
        if (cols % 64 != 0) row_mismatches += bits.back() >> (cols % 64) != 0 ? 1 : 0;
      }
      EXPECT_EQ(row_mismatches, 0) << kernels->level << ", rows of " << cols << " px";
    }
  }
  EXPECT_EQ(table.held_as_runs(), box.held_as_runs);
  // The boxes are neither empty nor everything, so a table of one value would fail.
  EXPECT_GT(inside, 10000);
  EXPECT_LT(inside, (1 << 24) - 10000);
}

// The stage's default boxes, and one narrow box per space whose edges lie inside the
// colour cube on every channel.
INSTANTIATE_TEST_SUITE_P(
    ColorRangeTable, EachBox,
    ::testing::Values(Box{"hsv", cv::COLOR_BGR2HSV, {18, 40, 50}, {40, 255, 255}, true},
                      Box{"lab", cv::COLOR_BGR2Lab, {50, 110, 140}, {255, 132, 255}, false},
                      Box{"bgr", -1, {0, 140, 160}, {255, 255, 255}, true},
                      Box{"hsv_narrow", cv::COLOR_BGR2HSV, {10, 100, 90}, {16, 150, 130}, true},
                      Box{"lab_narrow", cv::COLOR_BGR2Lab, {80, 130, 140}, {110, 145, 155}, false},
                      Box{"bgr_narrow", -1, {40, 60, 90}, {70, 100, 130}, true}),
    [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace tilth::segmentation
