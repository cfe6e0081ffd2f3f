// A binary image packed 64 pixels to a word (pixel x of a row is bit x % 64 of word
// x / 64), for the segmentation's morphology: a square dilation or erosion of radius r
// costs about r word operations per 64 pixels in each direction.
#pragma once

#include <cstdint>
#include <vector>

namespace tilth::segmentation {

class BitMask {
 public:
  // Contents undefined afterwards; the buffer is kept when it is large enough.
  void resize(int rows, int cols);

  int rows() const { return rows_; }
  int cols() const { return cols_; }
  int words_per_row() const { return words_per_row_; }
  // Bits beyond cols() in a row's last word must be 0 (dilate and erode keep them so).
  std::uint64_t* row(int y) { return words_.data() + static_cast<std::size_t>(y) * words_per_row_; }
  const std::uint64_t* row(int y) const {
    return words_.data() + static_cast<std::size_t>(y) * words_per_row_;
  }
  bool at(int y, int x) const { return (row(y)[x / 64] >> (x % 64)) & 1; }

  // As cv::dilate / cv::erode with a (2 radius + 1)^2 square and OpenCV's default border:
  // outside the image counts as 0 for the dilation, as 1 for the erosion. `scratch`
  // keeps its buffer between calls.
  void dilate(int radius, BitMask& scratch);
  void erode(int radius, BitMask& scratch);

 private:
  template <bool kErode>
  void square(int radius, BitMask& scratch);

  int rows_ = 0;
  int cols_ = 0;
  int words_per_row_ = 0;
  std::vector<std::uint64_t> words_;
};

}  // namespace tilth::segmentation
