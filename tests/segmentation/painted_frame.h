// A frame painted by hand for the segmentation tests: colours and depths set per
// rectangle, every colour trusted, so that the right mask is known pixel for pixel; and
// one call that runs a segmentation stage on it.
#pragma once

#include <memory>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/testing/stage_harness.h"

namespace tilth::segmentation {

struct PaintedFrame {
  std::shared_ptr<RegisteredColor> color = std::make_shared<RegisteredColor>();
  std::shared_ptr<DepthImage> depth = std::make_shared<DepthImage>();

  PaintedFrame(cv::Size size, const cv::Vec3b& bgr, float depth_mm) {
    color->bgr = cv::Mat(size, CV_8UC3, cv::Scalar(bgr));
    color->status = cv::Mat(size, CV_8UC1, cv::Scalar(RegisteredColor::kValid));
    depth->mm = cv::Mat(size, CV_32FC1, cv::Scalar(depth_mm));
  }
  void paint(const cv::Rect& area, const cv::Vec3b& bgr) {
    color->bgr(area).setTo(cv::Scalar(bgr));
  }
  void paint(const cv::Rect& area, const cv::Vec3b& bgr, float depth_mm) {
    paint(area, bgr);
    depth->mm(area).setTo(depth_mm);
  }
};

struct Segmented {
  cv::Mat mask;
  cv::Mat soil_depth_mm;
};

inline Segmented segment(const StageDescriptor& stage, const nlohmann::json& params,
                         const PaintedFrame& frame) {
  testing::TransformHarness harness(stage, params);
  const auto out = harness.run({frame.color, frame.depth});
  return {out[0].get<ResidueMask>().values.clone(), out[1].get<DepthImage>().mm.clone()};
}

inline int count_equal(const cv::Mat& mask, std::uint8_t value) {
  return cv::countNonZero(mask == value);
}

}  // namespace tilth::segmentation
