// Steps in the ground: straight lines across it where the soil's level jumps, as a
// cultivator's pass, a wheel track or a terrace leaves them. estimation.ground_plane fits
// the ground on the tool's side of them, so that it can average the soil widely without
// averaging two levels.
#pragma once

#include <optional>
#include <span>

namespace tilth::estimation {

// A point of the ground as the search sees it: where it lies across the ground from the
// tool point, and its level (the residual from a surface fitted to the whole ground).
struct LevelPoint {
  double x_mm;
  double y_mm;
  double level_mm;
};

// The line x cos + y sin = at_mm (x, y from the tool point), the level beyond it
// (x cos + y sin > at_mm) less the level before it, and which side the tool stands on.
struct GroundStep {
  double cos_angle;
  double sin_angle;
  double at_mm;
  double height_mm;
  // The tool point's side: beyond the line when it lies before it (at_mm < 0), and for a
  // line through the tool point the side whose level is the surface's there.
  bool tool_beyond;

  double across_mm(double x_mm, double y_mm) const { return x_mm * cos_angle + y_mm * sin_angle; }
  // Whether a point lies on the other side of the line than the tool.
  bool cuts_off(double x_mm, double y_mm) const {
    return (across_mm(x_mm, y_mm) > at_mm) != tool_beyond;
  }
};

// The highest step among `points`, or nullopt. A step is a straight line, in any
// direction, across which the level jumps in every 40 mm piece of it but one in three
// (at least one; at least four pieces), by at least min_height_mm and three times the
// median jump across the lines that way (on rough ground a step must stand out of the
// roughness), with the level on either side flat within 35 % of the jump over 16 mm. Relief, clods
// and residue the segmentation let through jump in a few pieces, and a wave of the relief is not
// flat on either side of its slope.
std::optional<GroundStep> highest_step(std::span<const LevelPoint> points, double min_height_mm);

}  // namespace tilth::estimation
