// The residue segmentation's per-pixel tests, 64 pixels at a time as the bits
// of one BitMask word (pixel i of the run is bit i), sixteen at a time.
#pragma once

#include <cstdint>

namespace tilth::segmentation {

// Bit i set where bytes[i] is 255 (a cv::inRange result; any byte >= 128 counts);
// `count` <= 64 pixels.
std::uint64_t marked_bits(const std::uint8_t* bytes, int count);

// Bit i set where status[i] is RegisteredColor::kValid; `count` <= 64 pixels.
std::uint64_t valid_status_bits(const std::uint8_t* status, int count);

}  // namespace tilth::segmentation
