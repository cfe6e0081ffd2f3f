// The residue segmentation's per-pixel tests and outputs, 64 pixels at a time as the bits
// of one BitMask word (pixel i of the run is bit i), SIMD where the test allows it.
#pragma once

#include <cstdint>

namespace tilth::segmentation {

// Bit i set where bytes[i] is 255 (a cv::inRange result; any byte >= 128 counts);
// `count` <= 64 pixels.
std::uint64_t marked_bits(const std::uint8_t* bytes, int count);

// Bit i set where status[i] is RegisteredColor::kValid; `count` <= 64 pixels.
std::uint64_t valid_status_bits(const std::uint8_t* status, int count);

// One row of the outputs: a pixel is ResidueMask::kUnknown where its `unknown` bit is set
// or its depth is NaN, otherwise kResidue where its `residue` bit is set, otherwise kSoil;
// its soil depth is depth_mm where the mask says kSoil, NaN elsewhere. `unknown` and
// `residue` hold (cols + 63) / 64 words.
void write_residue_row(const std::uint64_t* unknown, const std::uint64_t* residue,
                       const float* depth_mm, int cols, std::uint8_t* mask, float* soil_mm);

}  // namespace tilth::segmentation
