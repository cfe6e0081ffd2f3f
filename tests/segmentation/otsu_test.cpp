// Otsu's threshold against histograms whose split can be worked out by hand.
#include "otsu.h"

#include <vector>

#include <gtest/gtest.h>

namespace tilth::segmentation {
namespace {

// Counts 4, 0, 1, 3 in bins 0..3: total 8, first moment 0*4 + 2*1 + 3*3 = 11. The
// between-class variance of the split before bin t is (11/8 * w0 - m0)^2 / (w0 * w1):
//   t = 1: w0 = 4, m0 = 0: (5.5)^2 / (4 * 4)   = 1.890625
//   t = 2: the same split (bin 1 is empty)     = 1.890625
//   t = 3: w0 = 5, m0 = 2: (4.875)^2 / (5 * 3) = 1.584375
// The maximum is the plateau t = 1..2, whose middle is bin 2: the lower class is bin 0
// (mean 0), the upper bins 2 and 3 (mean 11/4, half of the count).
TEST(Otsu, SplitsAHandComputedHistogram) {
  const std::vector<double> histogram = {4, 0, 1, 3};
  const auto split = otsu_split(histogram);
  ASSERT_TRUE(split);
  EXPECT_EQ(split->threshold_bin, 2);
  EXPECT_DOUBLE_EQ(split->lower_mean, 0.0);
  EXPECT_DOUBLE_EQ(split->upper_mean, 2.75);
  EXPECT_DOUBLE_EQ(split->upper_fraction, 0.5);
}

// Two spikes, at bins 10 (3 pixels) and 20 (1 pixel): every threshold from 11 to 20 makes
// the same split, and the middle one, 16, lies halfway between them.
TEST(Otsu, TakesTheMiddleOfAPlateauBetweenTwoSpikes) {
  std::vector<double> histogram(32, 0.0);
  histogram[10] = 3;
  histogram[20] = 1;
  const auto split = otsu_split(histogram);
  ASSERT_TRUE(split);
  EXPECT_EQ(split->threshold_bin, 16);
  EXPECT_DOUBLE_EQ(split->lower_mean, 10.0);
  EXPECT_DOUBLE_EQ(split->upper_mean, 20.0);
  EXPECT_DOUBLE_EQ(split->upper_fraction, 0.25);
}

// Counts 1, 2, 1 in bins 0..2, symmetric: t = 1 gives (1 - 0)^2 / (1 * 3) = 1/3, t = 2 gives
// (3 - 2)^2 / (3 * 1) = 1/3 too: the plateau 1..2 has middle 2 (rounding up).
TEST(Otsu, SymmetricHistogramSplitsAtItsCentre) {
  const std::vector<double> histogram = {1, 2, 1};
  const auto split = otsu_split(histogram);
  ASSERT_TRUE(split);
  EXPECT_EQ(split->threshold_bin, 2);
  EXPECT_DOUBLE_EQ(split->lower_mean, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(split->upper_mean, 2.0);
}

TEST(Otsu, NothingToSplitInOneOrNoOccupiedBin) {
  EXPECT_FALSE(otsu_split(std::vector<double>{0, 0, 0}));
  EXPECT_FALSE(otsu_split(std::vector<double>{0, 7, 0}));
  EXPECT_FALSE(otsu_split(std::vector<double>{}));
}

}  // namespace
}  // namespace tilth::segmentation
