// The choice among a kernel family's levels (kernel_levels/kernel_levels.h): the widest
// the CPU runs, one named by hand, or those TILTH_KERNEL_LEVEL allows.
#include "kernel_levels/kernel_levels.h"

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

namespace tilth {
namespace {

struct FakeKernels {
  const char* level;
};

const FakeKernels kV3{"x86-64-v3"};
const FakeKernels kBaseline{"baseline"};

class KernelLevelsTest : public ::testing::Test {
 protected:
  void TearDown() override { unsetenv("TILTH_KERNEL_LEVEL"); }
};

TEST_F(KernelLevelsTest, AutoIsTheWidestLevelTheCpuRuns) {
  const KernelLevels<FakeKernels> levels{&kV3, &kBaseline};
  EXPECT_EQ(levels.choices(), (std::vector<std::string>{"auto", "x86-64-v3", "baseline"}));
  EXPECT_EQ(&levels.pick("auto"), cpu_runs_level("x86-64-v3") ? &kV3 : &kBaseline);
  EXPECT_EQ(&levels.pick("baseline"), &kBaseline);
}

TEST_F(KernelLevelsTest, TheEnvironmentHoldsEveryFamilyToALevel) {
  setenv("TILTH_KERNEL_LEVEL", "baseline", 1);
  const KernelLevels<FakeKernels> levels{&kV3, &kBaseline};
  ASSERT_EQ(levels.runnable().size(), 1u);
  EXPECT_EQ(&levels.pick("auto"), &kBaseline);
  EXPECT_EQ(levels.choices().size(), 3u);  // every level built is still named
}

TEST_F(KernelLevelsTest, ALevelNotBuiltInTheEnvironmentIsAnError) {
  setenv("TILTH_KERNEL_LEVEL", "x86-64-v4", 1);
  try {
    const KernelLevels<FakeKernels> levels{&kV3, &kBaseline};
    ADD_FAILURE() << "x86-64-v4 was accepted";
  } catch (const Error& error) {
    EXPECT_STREQ(error.what(),
                 "TILTH_KERNEL_LEVEL is 'x86-64-v4', not a level built: x86-64-v3, baseline");
  }
}

}  // namespace
}  // namespace tilth
