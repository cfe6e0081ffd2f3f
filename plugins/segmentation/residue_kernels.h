// The residue segmentation's per-row loops that gain from wide vectors: the in-range
// test of a colour box (ColorRangeTable), and the rows of the outputs. residue_kernels.cpp
// is compiled once per instruction-set level (kernel_levels/kernel_levels.h); the stages
// use the widest the CPU runs.
#pragma once

#include <cstdint>
#include <span>

namespace tilth::segmentation {

// For a green and red, the blues in the box: first | last << 8 (first > last: none).
using BlueRun = std::uint16_t;

struct ResidueKernels {
  // Bit i % 64 of bits[i / 64] set where BGR pixel i of `count` (3 bytes each) lies in the box
  // of `runs`, indexed by green + 256 * red, which holds one entry more than that, so
  // that each run can be read as a word. Bits from `count` on in the last word are 0.
  void (*in_runs)(const BlueRun* runs, const std::uint8_t* bgr, int count, std::uint64_t* bits);
  // The same for a box held as a byte per colour b | g << 8 | r << 16, not 0 inside; the
  // table holds 3 bytes more, so that each entry can be read as a word.
  void (*in_table)(const std::uint8_t* table, const std::uint8_t* bgr, int count,
                   std::uint64_t* bits);
  // One row of the outputs: a pixel is ResidueMask::kUnknown where its `unknown` bit is
  // set or its depth is NaN, otherwise kResidue where its `residue` bit is set, otherwise
  // kSoil; its soil depth is depth_mm where the mask says kSoil, NaN elsewhere.
  // `unknown` and `residue` hold (cols + 63) / 64 words.
  void (*write_residue_row)(const std::uint64_t* unknown, const std::uint64_t* residue,
                            const float* depth_mm, int cols, std::uint8_t* mask, float* soil_mm);
  const char* level;  // "x86-64-v3", "baseline"
};

// The levels this CPU runs, widest first: the stages use the first.
std::span<const ResidueKernels* const> available_residue_kernels();

}  // namespace tilth::segmentation
