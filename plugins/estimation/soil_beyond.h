// How much of the soil lies beyond the ground measured, on every side of the point it is
// measured at. Residue lies on the soil, so a ground with soil beyond it all around is
// residue taken for soil (pale straw on pale soil, colour clusters the wrong way round).
// A step, a rut or a furrow that does not pass through the point puts soil beyond it in
// three of the four quadrants around it at most (the quadrant facing away from it lies
// wholly on the near side), and a tilt in two.
#pragma once

#include <array>

namespace tilth::estimation {

class SoilBeyond {
 public:
  // Soil deeper than the ground by more than `beyond_mm` lies beyond it.
  explicit SoilBeyond(double beyond_mm) : beyond_mm_(beyond_mm) {}

  // A soil point `dx`, `dy` across the ground from the measuring point (in any unit),
  // `deeper_than_ground_mm` deeper than the ground there (negative: nearer).
  void add(double dx, double dy, double deeper_than_ground_mm, double weight = 1.0) {
    const int quadrant = (dx > 0 ? 1 : 0) + (dy > 0 ? 2 : 0);
    weight_[quadrant] += weight;
    if (deeper_than_ground_mm > beyond_mm_) beyond_[quadrant] += weight;
  }

  // The least share of the soil (by weight) lying beyond the ground among the four
  // quadrants around the measuring point; 0 unless each holds at least kMinQuadrantShare
  // of the soil.
  double least_share() const;

  double beyond_mm() const { return beyond_mm_; }

  // A quadrant with less soil than this tells nothing (residue or the region's edge may
  // hide it), and without it the other three cannot tell residue from a step.
  static constexpr double kMinQuadrantShare = 0.05;

 private:
  double beyond_mm_;
  std::array<double, 4> weight_{};
  std::array<double, 4> beyond_{};
};

}  // namespace tilth::estimation
