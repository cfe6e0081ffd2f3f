#include "alignment_overlay.h"

#include <opencv2/imgproc.hpp>

namespace tilth::calibrate {
namespace {

const cv::Vec3b kDepthEdge{255, 0, 255};
const cv::Vec3b kColorEdge{0, 255, 0};
const cv::Vec3b kBothEdges{255, 255, 255};

}  // namespace

cv::Mat alignment_overlay(const cv::Mat& bgr, const cv::Mat& depth_edges,
                          const cv::Mat& color_edges, const std::string& caption) {
  cv::Mat picture = bgr * 0.6;
  for (int v = 0; v < picture.rows; ++v) {
    for (int u = 0; u < picture.cols; ++u) {
      const bool depth = depth_edges.at<std::uint8_t>(v, u) != 0;
      const bool color = color_edges.at<std::uint8_t>(v, u) != 0;
      if (depth || color) {
        picture.at<cv::Vec3b>(v, u) = depth && color ? kBothEdges : depth ? kDepthEdge : kColorEdge;
      }
    }
  }
  cv::Mat scaled;
  cv::resize(picture, scaled, {}, kOverlayScale, kOverlayScale, cv::INTER_NEAREST);
  const cv::Point at{8, 24};
  cv::putText(scaled, caption, at, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 4);
  cv::putText(scaled, caption, at, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(255, 255, 255), 1);
  return scaled;
}

}  // namespace tilth::calibrate
