#include "pixel_classifier/pixel_features.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace tilth::segmentation {
namespace {

constexpr int kLevels = 1 << kCellBits;
constexpr int kShift = 8 - kCellBits;
// As segmentation.lab_clusters: below this lightness the ratios would amplify noise.
constexpr float kMinLightness = 10.0f;

cv::Mat compute_cell_features() {
  // Every cell's centre colour as one pixel of a kLevels^2 x kLevels image, cell order.
  cv::Mat centres(kLevels * kLevels, kLevels, CV_32FC3);
  for (int cell = 0; cell < kCellCount; ++cell) {
    const int b = cell >> (2 * kCellBits);
    const int g = (cell >> kCellBits) & (kLevels - 1);
    const int r = cell & (kLevels - 1);
    auto centre = [](int level) { return ((level << kShift) + (1 << kShift) / 2.0f) / 255.0f; };
    centres.at<cv::Vec3f>(cell / kLevels, cell % kLevels) = {centre(b), centre(g), centre(r)};
  }
  cv::Mat lab, hsv;
  cv::cvtColor(centres, lab, cv::COLOR_BGR2Lab);
  cv::cvtColor(centres, hsv, cv::COLOR_BGR2HSV);
  const int count = static_cast<int>(pixel_feature_names().size());
  cv::Mat features(kCellCount, count, CV_32FC1);
  for (int cell = 0; cell < kCellCount; ++cell) {
    const cv::Point at(cell % kLevels, cell / kLevels);
    const cv::Vec3f bgr = centres.at<cv::Vec3f>(at);
    const cv::Vec3f l = lab.at<cv::Vec3f>(at);
    const cv::Vec3f h = hsv.at<cv::Vec3f>(at);
    const float sum = bgr[0] + bgr[1] + bgr[2];
    const float per_lightness = 100.0f / std::max(l[0], kMinLightness);
    const float row[] = {l[0],
                         l[1],
                         l[2],
                         h[0],
                         h[1],
                         h[2],
                         (2 * bgr[1] - bgr[2] - bgr[0]) / sum,
                         l[1] * per_lightness,
                         l[2] * per_lightness};
    std::copy(std::begin(row), std::end(row), features.ptr<float>(cell));
  }
  return features;
}

}  // namespace

const std::vector<std::string>& pixel_feature_names() {
  static const std::vector<std::string> names = {"L*", "a*",  "b*",    "H",    "S",
                                                 "V",  "exg", "a*/L*", "b*/L*"};
  return names;
}

void color_cells(const cv::Mat& bgr, cv::Mat& cells) {
  thread_local cv::Mat mean;
  const int side = 2 * kFeatureSmoothingPx + 1;
  cv::blur(bgr, mean, {side, side}, {-1, -1}, cv::BORDER_REFLECT);
  cells.create(bgr.size(), CV_32SC1);
  for (int row = 0; row < bgr.rows; ++row) {
    const auto* in = mean.ptr<cv::Vec3b>(row);
    auto* out = cells.ptr<std::int32_t>(row);
    for (int col = 0; col < bgr.cols; ++col) {
      out[col] = ((in[col][0] >> kShift) << (2 * kCellBits)) |
                 ((in[col][1] >> kShift) << kCellBits) | (in[col][2] >> kShift);
    }
  }
}

const cv::Mat& cell_features() {
  static const cv::Mat features = compute_cell_features();
  return features;
}

}  // namespace tilth::segmentation
