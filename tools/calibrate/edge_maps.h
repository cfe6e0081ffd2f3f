// The two edge maps a calibration check compares, both on the depth camera's pixel grid:
// where the depth jumps (the silhouettes of straw, stubble and boards) and where the
// colour registered onto that grid changes. A good calibration puts them on each other.
// Each edge pixel carries its direction, so that an edge is matched only with edges of
// its own orientation and polarity: a straw's outline with the straw's colour edge, not
// with the edge of the shadow it casts beside it.
#pragma once

#include <cstdint>

#include <opencv2/core/mat.hpp>

namespace tilth::calibrate {

// Central differences (two pixels apart, so a mixed ToF pixel halfway up a jump does not
// split it) beyond this are depth edges. The simulated range noise (1 mm at 500 mm) puts
// a difference's spread at 1.5 mm: 6 mm is four of them, a few tens of false pixels a
// frame on bare soil (the tails beyond four spreads), while a straw resting on straw or a stalk
// standing out of the soil jumps more.
constexpr double kDepthJumpMm = 6.0;

// Canny's thresholds on the grey registered colour (3x3 Sobel, L2 gradient): a step of
// about 25 grey levels starts an edge, 12 continues one. Straw on soil steps by 60-100;
// the sensor noise (2 levels) and the soil's texture stay below.
constexpr double kColorEdgeLow = 50.0;
constexpr double kColorEdgeHigh = 100.0;

// An edge map: CV_8UC1, 0 off an edge, 1 + the sector of the edge's direction on one:
// 8 sectors of 45 degrees, sector s centred on s * 45 degrees from the +u axis towards
// +v. A depth edge points to its near side (up the surface, towards the camera), a colour
// edge to its brighter side.
constexpr int kSectors = 8;
std::uint8_t edge_sector(double du, double dv);

// Where the depth (CV_32FC1 mm, NaN = none) differs by more than `jump_mm` between the
// pixel's two neighbours left and right, or above and below (both valid). An exact step
// between two pixels marks both, so the edge is centred on the step.
cv::Mat depth_edges(const cv::Mat& depth_mm, double jump_mm = kDepthJumpMm);

// CV_8UC1, 255 where the colour's pixels are valid (registration status kValid) and so
// are all their 8 neighbours: edges found there come from what the colour camera saw,
// not from where the registration left black pixels.
cv::Mat color_region(const cv::Mat& status);

// The Canny edges of the grey colour (CV_8UC3 BGR) inside `region`.
cv::Mat color_edges(const cv::Mat& bgr, const cv::Mat& region);

}  // namespace tilth::calibrate
