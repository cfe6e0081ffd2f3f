// The `roi` parameter of the segmentation and estimation stages: the part of the depth
// image a stage works on. One chain passes one value to both (the chain file's `roi`
// variable), so that the segmentation segments what the estimator reads.
#pragma once

#include <optional>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include "tilth/param_spec.h"

namespace tilth {

class RegionOfInterest {
 public:
  enum class Whole { kImage, kMiddleHalf };

  // `value`: null for `when_null`, "image", "middle_half" (of the image in each
  // direction), or {"x", "y", "width", "height"} in depth pixels. Throws tilth::Error
  // naming the parameter when the value has another shape.
  RegionOfInterest(const nlohmann::json& value, Whole when_null);

  // The region on an image of `size`, clipped to it; throws tilth::Error when no pixel of
  // it lies in the image.
  cv::Rect on(cv::Size image) const;
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
