// How far the depth edges lie from the colour edges, for every shift of the colour edge
// map within a search window: the distance from each depth edge pixel to the nearest
// colour edge, sampled at the pixel moved by the shift. The shift that brings the two
// maps together is the registration's misalignment, in depth pixels.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "edge_maps.h"

namespace tilth::calibrate {

// Shifts searched, in depth pixels each way: a rig knocked by 1 degree (fx 510) is 9 px
// off, 2 degrees 18 px. A best shift on the window's rim means "at least this far off";
// beyond it no shift matches and the check cannot judge.
constexpr int kSearchRadiusPx = 20;

// Distances beyond this are a depth edge without a colour edge of its own (soil clods
// the colour of the soil, a straw on a straw) or paired with another's; capped, they
// weigh the same at every shift instead of pulling the match.
constexpr double kTruncationPx = 3.0;

// Distances are counted in bins of this width up to kHistogramRangePx (the last bin
// holds everything beyond): medians and 90th percentiles are read to a quarter pixel.
constexpr double kHistogramBinPx = 0.25;
constexpr double kHistogramRangePx = 16.0;

struct DistanceQuantiles {
  double median_px = 0.0;
  double p90_px = 0.0;
};

// Which colour edges a depth edge is matched with: those whose brighter side is the depth
// edge's near side (straw on soil), or its far side (dark stubble on pale soil). Each
// takes colour edges within 67.5 degrees of the expected direction.
enum class NearSide { kBrighter, kDarker };
const char* to_string(NearSide side);

// The distance of every pixel to the nearest colour edge of each direction.
class DirectedDistances {
 public:
  // `color_edges`: an edge map of edge_maps.h.
  explicit DirectedDistances(const cv::Mat& color_edges);

  // CV_32FC1: the distance to colour edges pointing within 67.5 degrees of `sector`.
  const cv::Mat& towards(int sector) const { return maps_[sector]; }
  std::uint64_t edge_pixels() const { return edge_pixels_; }

 private:
  std::array<cv::Mat, kSectors> maps_;
  std::uint64_t edge_pixels_ = 0;
};

// Sums over depth edge pixels, per shift; frames add up into the recording's.
class ShiftedDistances {
 public:
  ShiftedDistances();

  // `depth_edges`: an edge map of edge_maps.h, of the frame `color` was made from.
  void add_frame(const cv::Mat& depth_edges, const DirectedDistances& color, NearSide side);
  void add(const ShiftedDistances& other);

  // Depth edge pixels measured (at zero shift) and colour edge pixels seen.
  std::uint64_t depth_edge_pixels() const;
  std::uint64_t color_edge_pixels() const { return color_edge_pixels_; }

  // The mean of the distances capped at kTruncationPx: the cost a shift is chosen by.
  double cost(cv::Point shift) const;
  DistanceQuantiles quantiles(cv::Point shift) const;

  // The shift of least cost; ties go to the one nearest zero.
  cv::Point best_shift() const;
  // The best shift refined between pixels: per axis, the tip of the V through the
  // costs at the best shift and its two neighbours (a mean of capped distances falls off
  // linearly on both sides of a match). On the window's rim it stays whole.
  cv::Point2d best_offset() const;
  // How distinct the best shift is: 1 - its cost / the median cost over the window.
  // Near 0 when every shift matches as badly (no edges to go by, or texture only).
  double contrast() const;

 private:
  std::size_t index(cv::Point shift) const;

  std::vector<double> capped_sum_;        // per shift
  std::vector<std::uint64_t> count_;      // per shift: edge pixels moved inside the image
  std::vector<std::uint64_t> histogram_;  // per shift, per bin
  std::uint64_t color_edge_pixels_ = 0;
};

}  // namespace tilth::calibrate
