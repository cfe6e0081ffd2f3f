#include "bit_mask.h"

#include <algorithm>

namespace tilth::segmentation {

void BitMask::resize(int rows, int cols) {
  rows_ = rows;
  cols_ = cols;
  words_per_row_ = (cols + 63) / 64;
  words_.resize(static_cast<std::size_t>(rows) * words_per_row_);
}

void BitMask::dilate(int radius, BitMask& scratch) { square<false>(radius, scratch); }
void BitMask::erode(int radius, BitMask& scratch) { square<true>(radius, scratch); }

// A square is a row of 2r+1 pixels followed by a column of 2r+1: r steps of one pixel
// left and right along each row into `scratch`, then the 2r+1 rows around each row.
template <bool kErode>
void BitMask::square(int radius, BitMask& scratch) {
  if (radius <= 0 || rows_ == 0 || cols_ == 0) return;
  scratch.resize(rows_, cols_);
  const int words = words_per_row_;
  const std::uint64_t outside = kErode ? ~std::uint64_t{0} : 0;
  const std::uint64_t padding = cols_ % 64 == 0 ? 0 : ~((std::uint64_t{1} << (cols_ % 64)) - 1);
  const auto combine = [](std::uint64_t a, std::uint64_t b) { return kErode ? a & b : a | b; };

  for (int y = 0; y < rows_; ++y) {
    std::uint64_t* out = scratch.row(y);
    std::copy_n(row(y), words, out);
    for (int step = 0; step < radius; ++step) {
      out[words - 1] |= outside & padding;  // beyond the last column is outside too
      std::uint64_t previous = outside;     // the word to the left, before this step
      for (int i = 0; i < words; ++i) {
        const std::uint64_t word = out[i];
        const std::uint64_t next = i + 1 < words ? out[i + 1] : outside;
        const std::uint64_t left = (word << 1) | (previous >> 63);  // pixel x - 1, at x
        const std::uint64_t right = (word >> 1) | (next << 63);     // pixel x + 1, at x
        out[i] = combine(word, combine(left, right));
        previous = word;
      }
      out[words - 1] &= ~padding;
    }
  }

  for (int y = 0; y < rows_; ++y) {
    const int first = std::max(0, y - radius);
    const int last = std::min(rows_ - 1, y + radius);
    std::uint64_t* out = row(y);
    std::copy_n(scratch.row(first), words, out);
    for (int other = first + 1; other <= last; ++other) {
      const std::uint64_t* in = scratch.row(other);
      for (int i = 0; i < words; ++i) out[i] = combine(out[i], in[i]);
    }
  }
}

}  // namespace tilth::segmentation
