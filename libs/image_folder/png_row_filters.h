// PNG's row filters undone (PNG specification, clause 9): a row's bytes from its filtered
// bytes and the row above it.
#pragma once

#include <cstddef>
#include <cstdint>

namespace tilth::recording {

enum class PngFilter : std::uint8_t { kNone = 0, kSub = 1, kUp = 2, kAverage = 3, kPaeth = 4 };

inline constexpr std::uint8_t kPngFilterCount = 5;

// Undoes `filter` on `row` in place. `above` is the row above, already unfiltered (all
// zeros for the first row); `pixel_bytes` is the bytes of one pixel (at least 1).
void unfilter_png_row(PngFilter filter, std::uint8_t* row, const std::uint8_t* above,
                      std::size_t length, std::size_t pixel_bytes);

}  // namespace tilth::recording
