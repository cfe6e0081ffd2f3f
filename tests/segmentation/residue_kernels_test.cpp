// The outputs' rows (ResidueKernels::write_residue_row) at every instruction-set level this
// CPU runs, against the rule of residue_kernels.h applied pixel by pixel, on rows whose
// widths leave partial vectors and words.
#include "residue_kernels.h"

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "tilth/messages/residue_mask.h"

namespace tilth::segmentation {
namespace {

bool bit(const std::vector<std::uint64_t>& bits, int x) { return (bits[x / 64] >> (x % 64)) & 1; }

TEST(ResidueKernels, WriteResidueRowFollowsTheMaskRuleAtEveryLevel) {
  std::mt19937 random(7);
  for (const int cols : {640, 613, 64, 13}) {
    const auto words = static_cast<std::size_t>((cols + 63) / 64);
    std::vector<std::uint64_t> unknown(words), residue(words);
    for (std::size_t w = 0; w < words; ++w) {
      unknown[w] = (std::uint64_t{random()} << 32) | random();
      residue[w] = (std::uint64_t{random()} << 32) | random();
    }
    std::vector<float> depth(static_cast<std::size_t>(cols));
    std::uniform_real_distribution<float> mm(400.0f, 600.0f);
    for (int x = 0; x < cols; ++x) {
      depth[x] = random() % 5 == 0 ? std::numeric_limits<float>::quiet_NaN() : mm(random);
    }

    for (const ResidueKernels* kernels : available_residue_kernels()) {
      std::vector<std::uint8_t> mask(static_cast<std::size_t>(cols), 1);
      std::vector<float> soil(static_cast<std::size_t>(cols), -1.0f);
      kernels->write_residue_row(unknown.data(), residue.data(), depth.data(), cols, mask.data(),
                                 soil.data());
      int wrong = 0, soil_pixels = 0;
      for (int x = 0; x < cols; ++x) {
        const bool is_unknown = bit(unknown, x) || std::isnan(depth[x]);
        const bool is_soil = !is_unknown && !bit(residue, x);
        const std::uint8_t expected = is_unknown ? ResidueMask::kUnknown
                                      : is_soil  ? ResidueMask::kSoil
                                                 : ResidueMask::kResidue;
        wrong += mask[x] != expected ? 1 : 0;
        wrong += is_soil ? (soil[x] != depth[x] ? 1 : 0) : (std::isnan(soil[x]) ? 0 : 1);
        soil_pixels += is_soil ? 1 : 0;
      }
      EXPECT_EQ(wrong, 0) << kernels->level << ", " << cols << " px";
      EXPECT_GT(soil_pixels, 0) << kernels->level << ", " << cols << " px";
    }
  }
}

}  // namespace
}  // namespace tilth::segmentation
