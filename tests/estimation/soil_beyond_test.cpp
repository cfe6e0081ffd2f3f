// SoilBeyond (soil_beyond.h): the share of the soil beyond the ground, on the side of the
// measuring point where it is least.
#include "soil_beyond.h"

#include <gtest/gtest.h>

namespace tilth::estimation {
namespace {

// `beyond` of every 100 points of a quadrant lie 20 mm deeper, the rest on the ground.
void add_quadrant(SoilBeyond& soil, double dx, double dy, int beyond) {
  for (int i = 0; i < 100; ++i) soil.add(dx, dy, i < beyond ? 20.0 : 0.0);
}

TEST(SoilBeyond, TheLeastShareAmongTheQuadrants) {
  SoilBeyond soil(10.0);
  add_quadrant(soil, -1, -1, 10);
  add_quadrant(soil, 1, -1, 20);
  add_quadrant(soil, -1, 1, 30);
  add_quadrant(soil, 1, 1, 40);
  EXPECT_DOUBLE_EQ(soil.least_share(), 0.10);
}

// A step down, or a rut, beside the tool: soil beyond the ground on one side only.
TEST(SoilBeyond, SoilBeyondOnOneSideIsNoneOnEverySide) {
  SoilBeyond soil(10.0);
  add_quadrant(soil, -1, -1, 0);
  add_quadrant(soil, -1, 1, 0);
  add_quadrant(soil, 1, -1, 100);
  add_quadrant(soil, 1, 1, 100);
  EXPECT_DOUBLE_EQ(soil.least_share(), 0.0);
}

// Only deeper by more than the threshold counts; nearer soil (negative) never does.
TEST(SoilBeyond, OnlyMoreThanTheThresholdDeeperIsBeyond) {
  SoilBeyond soil(10.0);
  for (const double dx : {-1.0, 1.0}) {
    for (const double dy : {-1.0, 1.0}) {
      soil.add(dx, dy, 10.0);
      soil.add(dx, dy, 10.01);
      soil.add(dx, dy, -30.0);
      soil.add(dx, dy, 0.0);
    }
  }
  EXPECT_DOUBLE_EQ(soil.least_share(), 0.25);
  EXPECT_DOUBLE_EQ(soil.beyond_mm(), 10.0);
}

// Residue covering a quadrant, or the region's edge near an off-axis tool point, leaves it
// a few soil points: they tell nothing, and the other three alone cannot tell residue from
// a step, so there is no verdict. The points weigh by their weights.
TEST(SoilBeyond, AQuadrantWithLittleSoilLeavesNoVerdict) {
  SoilBeyond soil(10.0);
  add_quadrant(soil, -1, -1, 50);
  add_quadrant(soil, 1, -1, 50);
  add_quadrant(soil, -1, 1, 50);
  soil.add(1, 1, 20.0, 15.0);  // 15 of 315: under kMinQuadrantShare, 5 %
  EXPECT_DOUBLE_EQ(soil.least_share(), 0.0);
  soil.add(1, 1, 0.0, 2.0);  // 17 of 317: over it; 15 of its 17 beyond
  EXPECT_DOUBLE_EQ(soil.least_share(), 0.5);
}

TEST(SoilBeyond, NoSoilNoShare) { EXPECT_DOUBLE_EQ(SoilBeyond(10.0).least_share(), 0.0); }

}  // namespace
}  // namespace tilth::estimation
