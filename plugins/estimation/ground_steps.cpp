#include "ground_steps.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <vector>

#include "upper_median.h"

namespace tilth::estimation {
namespace {

// Lines every 180 / kAngles degrees, each also sheared by kShears strips per piece (up to
// 8.5 deg, between the directions); the level is averaged in strips kStripMm wide along
// them, and a side is kStripsPerSide strips.
constexpr int kAngles = 12;
constexpr double kShears[] = {-1.5, -1.0, -0.5, 0.0, 0.5, 1.0, 1.5};
constexpr double kMaxShear = 1.5;
constexpr double kStripMm = 4.0;
constexpr int kStripsPerSide = 4;
// A line is cut into pieces kPieceMm long; a step jumps in at least kMinPieces of them, each
// side of each averaged over at least kMinSidePoints points.
constexpr double kPieceMm = 40.0;
constexpr std::size_t kMinPieces = 4;
constexpr float kMinSidePoints = 8;
// Either side of a step, the level varies by at most this fraction of its height.
constexpr double kMaxUnevenness = 0.35;
// A step jumps by at least this many times the median jump between neighbouring sides.
constexpr double kRoughness = 3.0;
// Levels this far off the surface are not ground (residue the segmentation let through).
constexpr double kLevelBandMm = 16.0;

// Pieces of a line that may fail to show its step (residue the segmentation let through,
// the noise of a side's mean): one in three, at least one.
int spared_pieces(int pieces) { return std::max(1, pieces / 3); }

// The jump every piece of a line shows but `spared`; 0 when they do not agree on its sign.
// `jumps` is reordered.
double weakest_jump(std::vector<double>& jumps, int spared) {
  const auto lowest = jumps.begin() + spared;
  std::nth_element(jumps.begin(), lowest, jumps.end());
  if (*lowest > 0) return *lowest;
  const auto highest = jumps.end() - 1 - spared;
  std::nth_element(jumps.begin(), highest, jumps.end());
  return *highest < 0 ? *highest : 0.0;
}

// The points of the ground, in floats, coordinate by coordinate.
struct GroundPoints {
  std::vector<float> x, y, level;

  void clear() {
    x.clear();
    y.clear();
    level.clear();
  }
};

// The levels along the lines of one direction: per piece, running sums over its strips,
// so that a side of any line is two look-ups.
class Strips {
 public:
  // Strips and pieces enough for points up to reach_mm from the tool point.
  void reach(double reach_mm) {
    strips_ = 2 * static_cast<int>(std::ceil(reach_mm / kStripMm)) + 1;
    pieces_ = 2 * static_cast<int>(std::ceil(reach_mm / kPieceMm)) + 1;
    margin_ = 2 * kStripsPerSide + static_cast<int>(std::ceil(kMaxShear * (pieces_ / 2 + 1)));
  }

  int strips() const { return strips_; }
  int pieces() const { return pieces_; }

  // The levels of `ground` along lines in the direction (c, s): across them x c + y s.
  void fill(const GroundPoints& ground, double c, double s) {
    const std::size_t cells = static_cast<std::size_t>(pieces_ * (strips_ + 1));
    sums_.assign(cells + 1, 0.0f);  // and a last cell for the points beyond the strips
    counts_.assign(cells + 1, 0.0f);
    locate(ground, c, s, cells);
    // Points next to each other fall in one strip: adding the list's two halves in turn
    // keeps each sum from waiting for the one before.
    const std::size_t count = ground.level.size();
    const std::size_t half = count / 2;
    for (std::size_t i = 0; i < half; ++i) {
      add(cell_[i], ground.level[i]);
      add(cell_[half + i], ground.level[half + i]);
    }
    if (count % 2 != 0) add(cell_.back(), ground.level.back());
    // Every side's mean, from running sums over the strips; NaN without enough points,
    // and in the margins beyond the strips.
    means_.assign(static_cast<std::size_t>(pieces_ * row()), kNoSide);
    for (int piece = 0; piece < pieces_; ++piece) {
      for (int strip = 1; strip <= strips_; ++strip) {
        sums_[at(piece, strip)] += sums_[at(piece, strip - 1)];
        counts_[at(piece, strip)] += counts_[at(piece, strip - 1)];
      }
      float* const means = writable_sides(piece);
      for (int first = 0; first + kStripsPerSide <= strips_; ++first) {
        const float count = counts_[at(piece, first + kStripsPerSide)] - counts_[at(piece, first)];
        if (count < kMinSidePoints) continue;
        means[first] = (sums_[at(piece, first + kStripsPerSide)] - sums_[at(piece, first)]) / count;
      }
    }
  }

  // The mean levels of the sides of `piece` by their first strip: NaN without enough
  // points; readable from -margin() to strips() + margin().
  const float* sides(int piece) const {
    return means_.data() + static_cast<std::ptrdiff_t>(piece * row() + margin_);
  }

 private:
  // Each point's cell, piece * (strips + 1) + strip (strips 1-based: running sums start at
  // 0), or `beyond` outside the strips; in floats, a vector of points at a time.
  void locate(const GroundPoints& ground, double c, double s, std::size_t beyond) {
    const auto across_x = static_cast<float>(c / kStripMm);
    const auto across_y = static_cast<float>(s / kStripMm);
    const auto along_x = static_cast<float>(-s / kPieceMm);
    const auto along_y = static_cast<float>(c / kPieceMm);
    // Shifted to be positive, so that truncation is floor.
    const auto across_0 = static_cast<float>(strips_ / 2 + 1);
    const auto along_0 = static_cast<float>(pieces_ / 2);
    const int strips = strips_, pieces = pieces_, outside = static_cast<int>(beyond);
    const std::size_t count = ground.level.size();
    cell_.resize(count);
    const float* const x = ground.x.data();
    const float* const y = ground.y.data();
    int* const cell = cell_.data();
    for (std::size_t i = 0; i < count; ++i) {
      const float across = x[i] * across_x + y[i] * across_y + across_0;
      const float along = x[i] * along_x + y[i] * along_y + along_0;
      const int strip = static_cast<int>(across);
      const int piece = static_cast<int>(along);
      const bool inside = (across >= 1) & (strip <= strips) & (along >= 0) & (piece < pieces);
      cell[i] = inside ? piece * (strips + 1) + strip : outside;
    }
  }

  void add(int cell, float level) {
    sums_[static_cast<std::size_t>(cell)] += level;
    counts_[static_cast<std::size_t>(cell)] += 1.0f;
  }

  float* writable_sides(int piece) {
    return means_.data() + static_cast<std::ptrdiff_t>(piece * row() + margin_);
  }
  int row() const { return strips_ + 1 + 2 * margin_; }

  std::size_t at(int piece, int boundary) const {
    return static_cast<std::size_t>(piece * (strips_ + 1) + boundary);
  }

  int strips_ = 0;
  int pieces_ = 0;
  int margin_ = 0;  // strips beyond either end that the sides of sheared lines reach
  static constexpr float kNoSide = std::numeric_limits<float>::quiet_NaN();

  // In float: four lanes a vector where the lines are counted.
  std::vector<float> sums_, counts_, means_;
  std::vector<int> cell_;  // per point
};

// Whether the tool point lies beyond the line at strip boundary `at` of the pieces' sides
// `rows`, at_mm from it: by where it lies, or for a line through it (within a strip), by
// which side's level is nearer the surface fitted there (the levels are its residuals).
bool tool_beyond(const std::vector<const float*>& rows, std::ptrdiff_t at, double at_mm) {
  if (std::abs(at_mm) >= kStripMm) return at_mm < 0;
  double before = 0, beyond = 0;
  for (const float* sides : rows) {
    const float jump = sides[at] - sides[at - kStripsPerSide];
    if (std::isnan(jump)) continue;
    before += sides[at - kStripsPerSide];
    beyond += sides[at];
  }
  return std::abs(beyond) < std::abs(before);
}

}  // namespace

std::optional<GroundStep> highest_step(std::span<const LevelPoint> points, double min_height_mm) {
  thread_local GroundPoints ground;
  thread_local std::vector<double> jumps, unevenness, differences;
  thread_local std::vector<const float*> rows;                         // per piece
  thread_local std::vector<int> counted, short_rising, short_falling;  // per line
  ground.clear();
  double reach_squared = 0.0;
  for (const LevelPoint& point : points) {
    if (!(std::abs(point.level_mm) <= kLevelBandMm) || !std::isfinite(point.x_mm) ||
        !std::isfinite(point.y_mm)) {
      continue;  // not ground, or no point at all
    }
    ground.x.push_back(static_cast<float>(point.x_mm));
    ground.y.push_back(static_cast<float>(point.y_mm));
    ground.level.push_back(static_cast<float>(point.level_mm));
    reach_squared = std::max(reach_squared, point.x_mm * point.x_mm + point.y_mm * point.y_mm);
  }
  thread_local Strips levels;  // its buffers kept from one frame to the next
  levels.reach(std::sqrt(reach_squared));
  const int strips = levels.strips(), pieces = levels.pieces();
  std::optional<GroundStep> highest;
  for (int angle = 0; angle < kAngles; ++angle) {
    const double radians = std::numbers::pi * angle / kAngles;
    const double c = std::cos(radians), s = std::sin(radians);
    levels.fill(ground, c, s);
    // How much the level of the ground varies from side to side of any line this way: on
    // rough ground a step must stand out of its roughness.
    differences.clear();
    for (int edge = 0; edge <= strips; edge += kStripsPerSide) {
      for (int piece = 0; piece < pieces; ++piece) {
        const float* sides = levels.sides(piece);
        const double jump = sides[edge] - sides[edge - kStripsPerSide];
        if (!std::isnan(jump)) differences.push_back(std::abs(jump));
      }
    }
    if (differences.empty()) continue;
    const double least_height = std::max(min_height_mm, kRoughness * upper_median(differences));
    const auto least = static_cast<float>(least_height);
    const auto edges = static_cast<std::size_t>(strips + 1);
    for (const double shear : kShears) {
      // Each piece's sides, shifted by where the line crosses it: this many strips from
      // where it crosses the middle piece.
      rows.clear();
      for (int piece = 0; piece < pieces; ++piece) {
        rows.push_back(levels.sides(piece) + std::lround(shear * (piece - pieces / 2 + 0.5)));
      }
      // Per line: its pieces, and those short of least_height rising and falling. A step
      // rises (or falls) by least_height in all pieces but one in three (spared_pieces).
      counted.assign(edges, 0);
      short_rising.assign(edges, 0);
      short_falling.assign(edges, 0);
      for (const float* sides : rows) {
        for (std::size_t edge = 0; edge < edges; ++edge) {
          const float jump =
              sides[edge] - sides[static_cast<std::ptrdiff_t>(edge) - kStripsPerSide];
          const int has = jump == jump;  // NaN: a side without enough points
          counted[edge] += has;
          short_rising[edge] += has & (jump < least);
          short_falling[edge] += has & (jump > -least);
        }
      }
      for (std::size_t edge = 0; edge < edges; ++edge) {
        const int spared = spared_pieces(counted[edge]);
        if (counted[edge] < static_cast<int>(kMinPieces) ||
            (short_rising[edge] > spared && short_falling[edge] > spared)) {
          continue;
        }
        const auto at = static_cast<std::ptrdiff_t>(edge);
        jumps.clear();
        for (const float* sides : rows) {
          const double jump = sides[at] - sides[at - kStripsPerSide];
          if (!std::isnan(jump)) jumps.push_back(jump);
        }
        const double height = weakest_jump(jumps, spared);
        if (std::abs(height) < least_height) continue;
        if (highest && std::abs(height) <= std::abs(highest->height_mm)) continue;
        // A step is flat on both sides; a wave of the relief across the line is not.
        unevenness.clear();
        for (const float* sides : rows) {
          const double far_before =
              std::abs(sides[at - kStripsPerSide] - sides[at - 2 * kStripsPerSide]);
          const double far_beyond = std::abs(sides[at] - sides[at + kStripsPerSide]);
          if (!std::isnan(far_before)) unevenness.push_back(far_before);
          if (!std::isnan(far_beyond)) unevenness.push_back(far_beyond);
        }
        if (unevenness.empty() || upper_median(unevenness) > kMaxUnevenness * std::abs(height))
          continue;
        // Across the line less `slope` times along it is constant: in (x, y), a line whose
        // normal is turned from (c, s) by atan(slope).
        const double slope = shear * kStripMm / kPieceMm;
        const double norm = std::hypot(1.0, slope);
        const double at_mm = (static_cast<int>(edge) - strips / 2) * kStripMm / norm;
        highest = GroundStep{(c + slope * s) / norm, (s - slope * c) / norm, at_mm, height,
                             tool_beyond(rows, at, at_mm)};
      }
    }
  }
  return highest;
}

}  // namespace tilth::estimation
