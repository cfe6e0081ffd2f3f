// A mask drawn on the colour image carried onto the depth grid by the measurement chain's
// own depth projection and registration (depth.projection, registration.projective with
// nearest sampling), run in this process: each depth pixel takes the class of the colour
// pixel that shows it, so an imported mask lines up with the registered colour exactly
// as the chain will see it.
#pragma once

#include <cstdint>
#include <memory>

#include <opencv2/core/mat.hpp>

#include "framework/stage_registry.h"
#include "tilth/calibration.h"

namespace tilth::tools {

class MaskRegistration {
 public:
  // Throws tilth::Error when the depth or registration plugin is not loaded.
  explicit MaskRegistration(const StageRegistry& registry);

  // `color_classes` (CV_8UC1, the colour camera's size: 255 residue, 0 soil, 128 unknown)
  // on the grid of `depth_gray` (the raw CV_16UC1 depth image), with `rig`: a depth pixel
  // the colour camera sees (registration status valid) takes the class of its nearest
  // colour pixel; one without depth, outside the colour image or occluded from the
  // colour camera is 128. Throws tilth::Error (the stages' messages) for images of other
  // sizes than the calibration's.
  cv::Mat to_depth_grid(const cv::Mat& depth_gray, const std::shared_ptr<const RigCalibration>& rig,
                        const cv::Mat& color_classes, std::uint64_t frame_id);

 private:
  StageInstance projection_;
  StageInstance registration_;
};

}  // namespace tilth::tools
