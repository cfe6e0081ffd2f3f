// The colour set: L*, a*, b*, H, S, V, exg, a*/L*, b*/L* of each pixel's smoothed colour.
#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "pixel_classifier/set_features.h"

namespace tilth::segmentation {
namespace {

// As segmentation.lab_clusters: below this lightness the ratios would amplify noise.
constexpr float kMinLightness = 10.0f;
// Half a DN: a black pixel has no chromaticity.
constexpr float kMinSum = 0.5f / 255.0f;

}  // namespace

void ColourPlanes::compute(const cv::Mat& smoothed) {
  smoothed.convertTo(unit_, CV_32FC3, 1.0 / 255.0);
  cv::cvtColor(unit_, lab_, cv::COLOR_BGR2Lab);
  cv::cvtColor(unit_, hsv_, cv::COLOR_BGR2HSV);
}

void ColourPlanes::at(int row, int col, float* out) const {
  const cv::Vec3f bgr = unit_.ptr<cv::Vec3f>(row)[col];
  const cv::Vec3f l = lab_.ptr<cv::Vec3f>(row)[col];
  const cv::Vec3f h = hsv_.ptr<cv::Vec3f>(row)[col];
  const float sum = std::max(bgr[0] + bgr[1] + bgr[2], kMinSum);
  const float per_lightness = 100.0f / std::max(l[0], kMinLightness);
  out[0] = l[0];
  out[1] = l[1];
  out[2] = l[2];
  out[3] = h[0];
  out[4] = h[1];
  out[5] = h[2];
  out[6] = (2 * bgr[1] - bgr[2] - bgr[0]) / sum;
  out[7] = l[1] * per_lightness;
  out[8] = l[2] * per_lightness;
}

}  // namespace tilth::segmentation
