// RankSelection against a full sort: every rank and every sum of the smallest values, on
// soil-like depths, on ties, on values spread over many orders of magnitude (so that most
// fall into one bin), and on one or two values. Exact comparisons: the selection finds the
// values themselves, and sums of floats on a 2^-16 grid are exact in double.
#include "rank_selection.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace tilth::estimation {
namespace {

// Mismatches of every rank and every prefix sum against the sorted values.
int mismatches(const std::vector<float>& values) {
  std::vector<float> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  RankSelection ranks;
  ranks.index(values);
  int wrong = 0;
  double prefix = 0.0;
  for (std::size_t k = 0; k < sorted.size(); ++k) {
    wrong += ranks.sum_of_smallest(k) == prefix ? 0 : 1;
    wrong += ranks.at_rank(k) == sorted[k] ? 0 : 1;
    prefix += sorted[k];
  }
  wrong += ranks.sum_of_smallest(sorted.size()) == prefix ? 0 : 1;
  return wrong;
}

// On a 2^-16 mm grid, as float depths of a few hundred mm are.
std::vector<float> soil_depths(int count, double noise_mm, double outlier_share) {
  cv::RNG random(static_cast<std::uint64_t>(count));
  std::vector<float> values;
  for (int i = 0; i < count; ++i) {
    const double depth = random.uniform(0.0, 1.0) < outlier_share
                             ? random.uniform(300.0, 500.0)
                             : 518.0 + random.gaussian(noise_mm);
    values.push_back(static_cast<float>(std::round(depth * 65536.0) / 65536.0));
  }
  return values;
}

TEST(RankSelection, EveryRankAndSumOfSoilDepthsWithOutliers) {
  EXPECT_EQ(mismatches(soil_depths(5000, 1.0, 0.2)), 0);
  EXPECT_EQ(mismatches(soil_depths(4999, 0.01, 0.0)), 0);  // narrower than a bin
}

TEST(RankSelection, TiesAndEqualValues) {
  std::vector<float> ties;
  for (int i = 0; i < 3000; ++i) ties.push_back(static_cast<float>(500 + (i * 7919) % 13));
  EXPECT_EQ(mismatches(ties), 0);
  EXPECT_EQ(mismatches(std::vector<float>(1000, 518.25f)), 0);
}

TEST(RankSelection, ValuesOverManyOrdersOfMagnitude) {
  // Nearly all of them fall into the first bin, which then holds the selection's work.
  std::vector<float> values;
  cv::RNG random(5);
  for (int i = 0; i < 2000; ++i) {
    values.push_back(static_cast<float>(std::ldexp(1.0, random.uniform(-20, 100))));
  }
  values.push_back(-3.0e38f);
  values.push_back(3.0e38f);
  std::vector<float> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  RankSelection ranks;
  ranks.index(values);
  int wrong = 0;
  for (std::size_t k = 0; k < sorted.size(); ++k) wrong += ranks.at_rank(k) == sorted[k] ? 0 : 1;
  EXPECT_EQ(wrong, 0);
}

TEST(RankSelection, OneAndTwoValues) {
  EXPECT_EQ(mismatches({518.0f}), 0);
  EXPECT_EQ(mismatches({519.5f, 518.0f}), 0);
}

TEST(RankSelection, ReindexingForgetsThePreviousValues) {
  RankSelection ranks;
  const std::vector<float> first = soil_depths(1000, 1.0, 0.0);
  const std::vector<float> second = {3.0f, 1.0f, 2.0f};
  ranks.index(first);
  ranks.index(second);
  EXPECT_EQ(ranks.at_rank(0), 1.0f);
  EXPECT_EQ(ranks.at_rank(2), 3.0f);
  EXPECT_EQ(ranks.sum_of_smallest(3), 6.0);
}

}  // namespace
}  // namespace tilth::estimation
