// Which colour pixels nearest sampling reads for a point, and how the vector loops read
// them: as keys computed for many points at once, and as one 32-bit word per point.
// Plain structs, free of OpenCV, for the per-level kernels (row_kernels.h).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace tilth::registration {

// The `span` x `span` pixels nearest a point (u, v) (0-based, (0,0) at the centre of the
// top-left pixel): the top-left one is x = clamp(floor(u + (1 - span) / 2 + 0.5), 0,
// width - span) and likewise y, identified by the key y * row_key + x * column_key +
// (y & 1) * odd_row + (x & 1) * odd_column.
struct Addressing {
  int span;
  int row_key;
  int column_key;
  int odd_row;
  int odd_column;
};

// The bytes nearest sampling reads for a key: p[o], p[o + 1], p[o + 2] at o = key >>
// key_shift, or, for a 2x2 quad (second_row != 0), p[o], p[o + 1], p[o + second_row],
// p[o + second_row + 1]; as a little-endian word, p[o] in its lowest byte. `sites` are
// the bytes of blue, the two greens and red in the word when the key's phase (key &
// phase_mask) is 0; at phase f they are at site ^ f, which is how a quad starting on an
// odd row or column sees a mosaic's tile.
struct PixelWord {
  const std::uint8_t* data;
  std::ptrdiff_t size;  // bytes from data that may be read, at least 4
  int key_shift;
  int phase_mask;
  std::ptrdiff_t second_row;
  std::array<int, 4> sites;  // blue, green, green, red
};

// Both, for one colour image.
struct NearestPixels {
  Addressing addressing;
  PixelWord word;
};

}  // namespace tilth::registration
