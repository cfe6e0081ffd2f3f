#include "edge_maps.h"

#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "tilth/messages/registered_color.h"

namespace tilth::calibrate {
namespace {

// The difference across the pixel along one axis; 0 when it is no jump.
float jump(float before, float after, double jump_mm) {
  if (std::isnan(before) || std::isnan(after) || std::abs(after - before) <= jump_mm) return 0.0f;
  return after - before;
}

}  // namespace

std::uint8_t edge_sector(double du, double dv) {
  const double turns = std::atan2(dv, du) / (2.0 * std::numbers::pi);
  const long sector = std::lround(turns * kSectors);
  return static_cast<std::uint8_t>(1 + ((sector % kSectors) + kSectors) % kSectors);
}

cv::Mat depth_edges(const cv::Mat& depth_mm, double jump_mm) {
  CV_Assert(depth_mm.type() == CV_32FC1);
  cv::Mat edges(depth_mm.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 1; v + 1 < depth_mm.rows; ++v) {
    const float* above = depth_mm.ptr<float>(v - 1);
    const float* row = depth_mm.ptr<float>(v);
    const float* below = depth_mm.ptr<float>(v + 1);
    std::uint8_t* out = edges.ptr<std::uint8_t>(v);
    for (int u = 1; u + 1 < depth_mm.cols; ++u) {
      const float across = jump(row[u - 1], row[u + 1], jump_mm);
      const float down = jump(above[u], below[u], jump_mm);
      // Towards the near side: against the depth's rise.
      if (across != 0.0f || down != 0.0f) out[u] = edge_sector(-across, -down);
    }
  }
  return edges;
}

cv::Mat color_region(const cv::Mat& status) {
  CV_Assert(status.type() == CV_8UC1);
  cv::Mat valid = status == RegisteredColor::kValid;
  cv::Mat region;
  cv::erode(valid, region, cv::Mat(), cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return region;
}

cv::Mat color_edges(const cv::Mat& bgr, const cv::Mat& region) {
  CV_Assert(bgr.type() == CV_8UC3 && region.size() == bgr.size());
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::Mat canny;
  cv::Canny(grey, canny, kColorEdgeLow, kColorEdgeHigh, 3, true);
  cv::Mat du;
  cv::Mat dv;
  cv::Sobel(grey, du, CV_16S, 1, 0, 3);
  cv::Sobel(grey, dv, CV_16S, 0, 1, 3);
  cv::Mat edges(bgr.size(), CV_8UC1, cv::Scalar(0));
  for (int v = 0; v < edges.rows; ++v) {
    for (int u = 0; u < edges.cols; ++u) {
      if (canny.at<std::uint8_t>(v, u) == 0 || region.at<std::uint8_t>(v, u) == 0) continue;
      edges.at<std::uint8_t>(v, u) = edge_sector(du.at<short>(v, u), dv.at<short>(v, u));
    }
  }
  return edges;
}

}  // namespace tilth::calibrate
