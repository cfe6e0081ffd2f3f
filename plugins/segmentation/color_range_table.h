// Which of the 2^24 BGR colours lie in a box of another colour space: built once per
// parameter set with OpenCV's own conversion and in-range test, so a lookup gives exactly
// what cv::cvtColor + cv::inRange would. The table is a byte per colour (16 MB, on 2 MB
// pages: a frame's colours lie on a thousand or more 4 KB pages, too many for the TLB),
// unless for every green and red the box holds one run of blues (true of the HSV boxes of
// soil and straw): then it is that run's first and last blue, 128 KB. Either is read with
// vector gathers where the CPU has them (ResidueKernels). A camera's noise spreads a frame's
// colours over much of the 16 MB, and the lookups then wait on memory.
#pragma once

#include <array>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "residue_kernels.h"

namespace tilth::segmentation {

class ColorRangeTable {
 public:
  // `conversion`: the cv::ColorConversionCodes from BGR into the box's space, or -1 when
  // the box is in BGR itself. `lower`, `upper`: inclusive 8-bit bounds per channel.
  ColorRangeTable(int conversion, const std::array<int, 3>& lower, const std::array<int, 3>& upper);

  // For `count` BGR pixels (3 bytes each): bit i % 64 of bits[i / 64] set where pixel i is
  // inside the box (where cv::inRange writes 255); bits from `count` on in the last word
  // are 0.
  void classify_row(const ResidueKernels& kernels, const std::uint8_t* bgr, int count,
                    std::uint64_t* bits) const;
  bool contains(std::uint8_t b, std::uint8_t g, std::uint8_t r) const;

  // Whether the table is held as one run of blues per (green, red), 128 KB, which the
  // caches keep, rather than 16 MB (see above).
  bool held_as_runs() const { return !runs_.empty(); }

 private:
  struct Free {
    void operator()(std::uint8_t* bytes) const { std::free(bytes); }
  };
  // Keeps runs_ instead of the byte table where each (green, red) has one run.
  void hold_as_runs_if_possible();

  std::unique_ptr<std::uint8_t[], Free> in_range_;  // null when held as runs
  std::vector<BlueRun> runs_;  // per green + 256 * red, and one entry of padding
};

}  // namespace tilth::segmentation
