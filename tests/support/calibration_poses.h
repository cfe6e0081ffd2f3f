// Board poses a careful user would hold up for a calibration: tilted, at working
// distances, near every corner and edge of the ToF image and in its middle, each wholly
// inside both cameras' images.
#pragma once

#include <cstdint>
#include <vector>

#include "checkerboard_renderer.h"

namespace tilth::testing {

// `count` poses, tilted 15 to 40 degrees about the board's axes (up to 12 about its
// normal), 550 to 1000 mm from the ToF camera (farther when the board would not fit),
// deterministic for a `seed`; fewer only when a rig sees too little for the board.
std::vector<BoardPose> calibration_poses(const RigCalibration& rig, const Checkerboard& board,
                                         int count, std::uint64_t seed);

// Whether the whole board, paper margin included, lies inside both images, `border_px`
// from their edges.
bool board_inside_both(const RigCalibration& rig, const Checkerboard& board, const BoardPose& pose,
                       double border_px);

}  // namespace tilth::testing
