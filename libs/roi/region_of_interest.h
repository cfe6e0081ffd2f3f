// The `roi` parameter of the registration, segmentation and estimation stages: the part
// of the depth image a stage works on. One chain passes one value to all (the chain
// file's `roi` variable), so that each stage prepares what the next one reads.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include "tilth/param_spec.h"

namespace tilth {

class RegionOfInterest {
 public:
  // How far around its region a segmentation stage reads (colour smoothing, speckle
  // removal and dilation, rounded up to whole 8-pixel steps): it segments around(image,
  // kMarginPx), and the registration colours that much.
  static constexpr int kMarginPx = 8;

  enum class Whole { kImage, kMiddleHalf };

  // `value`: null for `when_null`, "image", "middle_half" (of the image in each
  // direction), or {"x", "y", "width", "height"} in depth pixels. Throws tilth::Error
  // naming the parameter when the value has another shape.
  RegionOfInterest(const nlohmann::json& value, Whole when_null);

  // The region on an image of `size`, clipped to it; throws tilth::Error when no pixel of
  // it lies in the image.
  cv::Rect on(cv::Size image) const;
  // on(image) grown by `margin_px` on every side, clipped to the image.
  cv::Rect around(cv::Size image, int margin_px) const;
  // Whether on(image) cuts off part of the configured region.
  bool clipped_on(cv::Size image) const;
  // "roi x 600, y 400, 100x100 reaches outside the 640x480 image; using x 600, y 400, 40x80"
  std::string clipping_note(cv::Size image) const;

 private:
  cv::Rect unclipped_on(cv::Size image) const;

  Whole whole_ = Whole::kImage;
  std::optional<cv::Rect> pixels_;  // empty: whole_
};

// The `roi` parameter, with what null means for the stage.
ParamSpec roi_param(RegionOfInterest::Whole when_null);

}  // namespace tilth
