// Collecting a region's finite soil depths (SoilKernels::collect_finite) at every
// instruction-set level this CPU runs, against the depths taken one by one: rows of
// patches and of scattered NaN and infinities, whose widths leave partial vectors.
#include "soil_kernels.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace tilth::estimation {
namespace {

TEST(SoilKernels, CollectFiniteKeepsEveryFiniteDepthInOrderAtEveryLevel) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr float kInf = std::numeric_limits<float>::infinity();
  std::mt19937 random(11);
  std::uniform_real_distribution<float> mm(-50.0f, 700.0f);
  constexpr int kRows = 20;
  for (const int cols : {640, 613, 7}) {
    std::vector<float> depth(static_cast<std::size_t>(kRows * cols));
    for (std::size_t i = 0; i < depth.size(); ++i) {
      const bool in_patch = (i / 24) % 3 == 0;  // runs of 24 missing depths
      const int roll = static_cast<int>(random() % 10);
      depth[i] = in_patch    ? kNaN
                 : roll == 0 ? kNaN
                 : roll == 1 ? -kInf
                 : roll == 2 ? kInf
                             : mm(random);
    }
    std::vector<float> expected;
    float lowest = std::numeric_limits<float>::max(), highest = -lowest;
    for (const float value : depth) {
      if (!std::isfinite(value)) continue;
      expected.push_back(value);
      lowest = std::min(lowest, value);
      highest = std::max(highest, value);
    }
    ASSERT_GT(expected.size(), depth.size() / 4);

    for (const SoilKernels* kernels : available_soil_kernels()) {
      constexpr int kGuard = 8;  // past the slack: never written
      std::vector<float> collected(depth.size() + kSlack + kGuard, -1.0f);
      CollectedDepths state{collected.data(), std::numeric_limits<float>::max(),
                            -std::numeric_limits<float>::max()};
      for (int row = 0; row < kRows; ++row) {
        state = kernels->collect_finite(depth.data() + row * cols, cols, state);
      }
      const std::size_t written_up_to = expected.size() + kSlack;
      int guard_written = 0;
      for (std::size_t i = written_up_to; i < collected.size(); ++i) {
        guard_written += collected[i] != -1.0f ? 1 : 0;
      }
      EXPECT_EQ(guard_written, 0) << kernels->level;
      collected.resize(static_cast<std::size_t>(state.end - collected.data()));
      EXPECT_EQ(collected, expected) << kernels->level << ", " << cols << " px";
      EXPECT_EQ(state.lowest, lowest) << kernels->level;
      EXPECT_EQ(state.highest, highest) << kernels->level;
    }
  }
}

TEST(SoilKernels, NoFiniteDepthLeavesAnEmptyRange) {
  const std::vector<float> depth(100, std::numeric_limits<float>::quiet_NaN());
  for (const SoilKernels* kernels : available_soil_kernels()) {
    std::vector<float> collected(depth.size() + kSlack);
    const CollectedDepths state = kernels->collect_finite(
        depth.data(), static_cast<int>(depth.size()),
        {collected.data(), std::numeric_limits<float>::max(), -std::numeric_limits<float>::max()});
    EXPECT_EQ(state.end, collected.data()) << kernels->level;
    EXPECT_GT(state.lowest, state.highest) << kernels->level;
  }
}

}  // namespace
}  // namespace tilth::estimation
