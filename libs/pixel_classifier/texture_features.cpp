// The texture set: shading-invariant colour, luminance over the image's median, and at
// each window of kTextureWindowsPx the local mean, standard deviation and contrast of that
// luminance and the structure tensor of its gradient (energy and coherence: straw is
// linear). Every window sum is four look-ups in an integral image (in double: the sums of
// a whole image keep their precision), O(1) per pixel whatever the window, and made only
// for the pixels whose features are read.
#include <algorithm>
#include <cmath>
#include <iterator>

#include <opencv2/imgproc.hpp>

#include "pixel_classifier/pixel_features.h"
#include "pixel_classifier/set_features.h"

namespace tilth::segmentation {
namespace {

// The contrast's floor of the local deviation: 2 % of the median luminance, about the
// sensor noise after the 3x3 mean, so that flat areas do not amplify noise.
constexpr float kMinDeviation = 0.02f;
constexpr float kMinEnergy = 1e-6f;
constexpr int kWidestHalf =
    *std::max_element(std::begin(kTextureWindowsPx), std::end(kTextureWindowsPx)) / 2;

// log(v + 1) for every 8-bit value: the colour ratios' logarithms by table.
const std::array<float, 256>& log_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> values{};
    for (int v = 0; v < 256; ++v) values[v] = std::log(static_cast<float>(v + 1));
    return values;
  }();
  return table;
}

}  // namespace

void TexturePlanes::compute(const cv::Mat& smoothed, const cv::Rect& area, const cv::Mat& counted) {
  luminance(smoothed, luma_);
  // Centred on the median (c = Y/median - 1) so that the variance, a difference of two
  // window means, keeps its precision in float.
  luma_.convertTo(centred_, CV_32F, 1.0 / median_luminance(luma_(area), counted), -1.0);
  cv::Sobel(centred_, gx_, CV_32F, 1, 0, 3, 1, 0, cv::BORDER_REFLECT);
  cv::Sobel(centred_, gy_, CV_32F, 0, 1, 3, 1, 0, cv::BORDER_REFLECT);
  products_[kMean] = centred_;
  cv::multiply(centred_, centred_, products_[kSquare]);
  cv::multiply(gx_, gx_, products_[kXX]);
  cv::multiply(gy_, gy_, products_[kYY]);
  cv::multiply(gx_, gy_, products_[kXY]);
  for (int plane = 0; plane < kPlanes; ++plane) {
    // Around the area: the image's pixels where the surroundings hold them (OpenCV reads
    // past a view), reflected beyond the image's edges.
    cv::copyMakeBorder(products_[plane](area), padded_, kWidestHalf, kWidestHalf, kWidestHalf,
                       kWidestHalf, cv::BORDER_REFLECT);
    cv::integral(padded_, sums_[plane], CV_64F);
  }
  colour_ = smoothed(area);
  c_ = centred_(area);
  dx_ = gx_(area);
  dy_ = gy_(area);
}

// Inlined into at(), its only caller, where the 15 calls a pixel are half its features' cost.
[[gnu::always_inline]] inline float TexturePlanes::window_mean(int plane, int half, int row,
                                                               int col) const {
  const cv::Mat& sums = sums_[plane];
  const double* top = sums.ptr<double>(row + kWidestHalf - half);
  const double* bottom = sums.ptr<double>(row + kWidestHalf + half + 1);
  const int left = col + kWidestHalf - half, right = col + kWidestHalf + half + 1;
  const double sum = bottom[right] - top[right] - bottom[left] + top[left];
  const int side = 2 * half + 1;
  return static_cast<float>(sum / (side * side));
}

void TexturePlanes::at(int row, int col, float* out) const {
  const auto& logs = log_table();
  const cv::Vec3b bgr = colour_.ptr<cv::Vec3b>(row)[col];
  const float c = c_.ptr<float>(row)[col];
  const float dx = dx_.ptr<float>(row)[col], dy = dy_.ptr<float>(row)[col];
  const int b = bgr[0], g = bgr[1], r = bgr[2];
  const float sum = static_cast<float>(b + g + r + 3);
  const int high = std::max({b, g, r}), low = std::min({b, g, r});
  *out++ = c + 1.0f;
  *out++ = static_cast<float>(r + 1) / sum;
  *out++ = static_cast<float>(g + 1) / sum;
  *out++ = logs[r] - logs[g];
  *out++ = logs[b] - logs[g];
  *out++ = high == 0 ? 0.0f : static_cast<float>(high - low) / static_cast<float>(high);
  *out++ = std::sqrt(dx * dx + dy * dy);
  for (const int side : kTextureWindowsPx) {
    const int half = side / 2;
    const float mean = window_mean(kMean, half, row, col);
    const float deviation =
        std::sqrt(std::max(window_mean(kSquare, half, row, col) - mean * mean, 0.0f));
    const float jxx = window_mean(kXX, half, row, col), jyy = window_mean(kYY, half, row, col);
    const float jxy = window_mean(kXY, half, row, col);
    const float energy = jxx + jyy;
    *out++ = mean + 1.0f;
    *out++ = deviation;
    *out++ = (c - mean) / (deviation + kMinDeviation);
    *out++ = std::sqrt(energy);
    *out++ = std::sqrt((jxx - jyy) * (jxx - jyy) + 4 * jxy * jxy) / (energy + kMinEnergy);
  }
}

}  // namespace tilth::segmentation
