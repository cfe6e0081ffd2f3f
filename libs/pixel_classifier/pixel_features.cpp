#include "pixel_classifier/pixel_features.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>

#include <opencv2/imgproc.hpp>

namespace tilth::segmentation {

int feature_reach_px(FeatureSet set) {
  constexpr int kSobelPx = 1;
  const int widest = *std::max_element(std::begin(kTextureWindowsPx), std::end(kTextureWindowsPx));
  return kFeatureSmoothingPx + (set == FeatureSet::kColour ? 0 : kSobelPx + widest / 2);
}

void PixelFeatures::compute(FeatureSet set, const cv::Mat& bgr, const cv::Rect& area,
                            const cv::Mat& counted) {
  set_ = set;
  const int reach = feature_reach_px(set);
  const cv::Rect around =
      cv::Rect(area.x - reach, area.y - reach, area.width + 2 * reach, area.height + 2 * reach) &
      cv::Rect({}, bgr.size());
  smoothed_colour(bgr(around), smoothed_);
  const cv::Rect inside = area - around.tl();
  if (set == FeatureSet::kColour) {
    colour_.compute(smoothed_(inside));
  } else {
    texture_.compute(smoothed_, inside, counted);
  }
}

void PixelFeatures::at(int row, int col, float* out) const {
  if (set_ == FeatureSet::kColour) {
    colour_.at(row, col, out);
  } else {
    texture_.at(row, col, out);
  }
}

void pixel_features(FeatureSet set, const cv::Mat& bgr, const cv::Mat& counted, cv::Mat& features) {
  thread_local PixelFeatures planes;
  planes.compute(set, bgr, cv::Rect({}, bgr.size()), counted);
  features.create(static_cast<int>(bgr.total()), static_cast<int>(feature_names(set).size()),
                  CV_32FC1);
  for (int row = 0; row < bgr.rows; ++row) {
    for (int col = 0; col < bgr.cols; ++col) {
      planes.at(row, col, features.ptr<float>(row * bgr.cols + col));
    }
  }
}

void smoothed_colour(const cv::Mat& bgr, cv::Mat& smoothed) {
  const int side = 2 * kFeatureSmoothingPx + 1;
  cv::blur(bgr, smoothed, {side, side}, {-1, -1}, cv::BORDER_REFLECT);
}

void luminance(const cv::Mat& smoothed, cv::Mat& luminance_dn) {
  luminance_dn.create(smoothed.size(), CV_32FC1);
  for (int row = 0; row < smoothed.rows; ++row) {
    const auto* in = smoothed.ptr<cv::Vec3b>(row);
    auto* out = luminance_dn.ptr<float>(row);
    for (int col = 0; col < smoothed.cols; ++col) {
      out[col] = 0.114f * in[col][0] + 0.587f * in[col][1] + 0.299f * in[col][2];
    }
  }
}

float median_luminance(const cv::Mat& luminance_dn, const cv::Mat& counted) {
  std::array<std::uint32_t, 256> histogram{};
  std::uint64_t total = 0;
  for (int row = 0; row < luminance_dn.rows; ++row) {
    const auto* in = luminance_dn.ptr<float>(row);
    const auto* use = counted.empty() ? nullptr : counted.ptr<std::uint8_t>(row);
    for (int col = 0; col < luminance_dn.cols; ++col) {
      if (use && !use[col]) continue;
      ++histogram[std::clamp(static_cast<int>(std::lround(in[col])), 0, 255)];
      ++total;
    }
  }
  if (total == 0) return counted.empty() ? 1.0f : median_luminance(luminance_dn, cv::Mat());
  std::uint64_t below = 0;
  int level = 0;
  while (below + histogram[level] <= (total - 1) / 2) below += histogram[level++];
  return static_cast<float>(std::max(level, 1));
}

}  // namespace tilth::segmentation
