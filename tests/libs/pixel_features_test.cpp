// The texture features, computed with box filters, against a direct computation of their
// definitions (window loops, borders reflected) on a small random image; the colour set
// against the colours it describes; and the per-image normalisation's median.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "pixel_classifier/feature_set.h"
#include "pixel_classifier/pixel_features.h"

namespace tilth::segmentation {
namespace {

// A 40x31 image of straw-like streaks over noise: every feature varies.
cv::Mat test_image() {
  cv::Mat bgr(31, 40, CV_8UC3);
  cv::RNG(7).fill(bgr, cv::RNG::UNIFORM, 20, 200);
  for (int col = 3; col < 40; col += 9) bgr.col(col) = cv::Scalar(120, 190, 220);
  return bgr;
}

float at(const cv::Mat& plane, int row, int col) {
  return plane.at<float>(cv::borderInterpolate(row, plane.rows, cv::BORDER_REFLECT),
                         cv::borderInterpolate(col, plane.cols, cv::BORDER_REFLECT));
}

// Sobel's 3x3 derivative, written out.
float derivative(const cv::Mat& plane, int row, int col, bool along_x) {
  float sum = 0;
  for (int d = -1; d <= 1; ++d) {
    const float weight = d == 0 ? 2.0f : 1.0f;
    sum += along_x ? weight * (at(plane, row + d, col + 1) - at(plane, row + d, col - 1))
                   : weight * (at(plane, row + 1, col + d) - at(plane, row - 1, col + d));
  }
  return sum;
}

TEST(PixelFeatures, TextureEqualsItsDefinitionsComputedDirectly) {
  const cv::Mat bgr = test_image();
  cv::Mat features, smoothed, luma;
  pixel_features(FeatureSet::kTexture, bgr, cv::Mat(), features);
  smoothed_colour(bgr, smoothed);
  luminance(smoothed, luma);

  std::vector<float> sorted(luma.begin<float>(), luma.end<float>());
  for (float& value : sorted) value = std::round(value);
  std::nth_element(sorted.begin(), sorted.begin() + (sorted.size() - 1) / 2, sorted.end());
  const float median = sorted[(sorted.size() - 1) / 2];
  EXPECT_EQ(median_luminance(luma, cv::Mat()), median);

  const cv::Mat y = luma / median;
  const auto& names = feature_names(FeatureSet::kTexture);
  ASSERT_EQ(features.cols, static_cast<int>(names.size()));
  ASSERT_EQ(features.rows, bgr.rows * bgr.cols);
  for (int row = 0; row < bgr.rows; ++row) {
    for (int col = 0; col < bgr.cols; ++col) {
      const float* got = features.ptr<float>(row * bgr.cols + col);
      const cv::Vec3b c = smoothed.at<cv::Vec3b>(row, col);
      const float sum = c[0] + c[1] + c[2] + 3.0f;
      const float gx = derivative(y, row, col, true), gy = derivative(y, row, col, false);
      std::vector<float> want = {
          y.at<float>(row, col),
          (c[2] + 1) / sum,
          (c[1] + 1) / sum,
          std::log((c[2] + 1.0f) / (c[1] + 1.0f)),
          std::log((c[0] + 1.0f) / (c[1] + 1.0f)),
          static_cast<float>(std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]})) /
              std::max({c[0], c[1], c[2]}),
          std::hypot(gx, gy)};
      for (const int side : kTextureWindowsPx) {
        const int half = side / 2;
        double mean = 0, square = 0, xx = 0, yy = 0, xy = 0;
        for (int dr = -half; dr <= half; ++dr) {
          for (int dc = -half; dc <= half; ++dc) {
            const double v = at(y, row + dr, col + dc);
            // The window's gradients at reflected positions: Sobel of the reflected plane.
            const int r = cv::borderInterpolate(row + dr, y.rows, cv::BORDER_REFLECT);
            const int k = cv::borderInterpolate(col + dc, y.cols, cv::BORDER_REFLECT);
            const double dx = derivative(y, r, k, true), dy = derivative(y, r, k, false);
            mean += v;
            square += v * v;
            xx += dx * dx;
            yy += dy * dy;
            xy += dx * dy;
          }
        }
        const double n = side * side;
        mean /= n, square /= n, xx /= n, yy /= n, xy /= n;
        const double deviation = std::sqrt(std::max(square - mean * mean, 0.0));
        want.push_back(static_cast<float>(mean));
        want.push_back(static_cast<float>(deviation));
        want.push_back(static_cast<float>((y.at<float>(row, col) - mean) / (deviation + 0.02)));
        want.push_back(static_cast<float>(std::sqrt(xx + yy)));
        want.push_back(
            static_cast<float>(std::sqrt((xx - yy) * (xx - yy) + 4 * xy * xy) / (xx + yy + 1e-6)));
      }
      for (std::size_t i = 0; i < want.size(); ++i) {
        // Float window sums of ~500 terms; the contrast divides by a deviation >= 0.02.
        EXPECT_NEAR(got[i], want[i], 2e-4 * std::max(1.0f, std::abs(want[i])))
            << names[i] << " at row " << row << ", column " << col;
      }
    }
  }
}

// The features of an area are those of the whole image there: the windows at the area's
// edge see the image around it, not the area's reflection. (The whole image's median is
// taken over the area's pixels too.)
TEST(PixelFeatures, AreaHasTheWholeImagesFeatures) {
  const cv::Mat bgr = test_image();
  for (const cv::Rect area : {cv::Rect(14, 9, 12, 10), cv::Rect(0, 20, 40, 11)}) {
    cv::Mat in_area(bgr.size(), CV_8UC1, cv::Scalar(0)), whole;
    in_area(area).setTo(255);
    pixel_features(FeatureSet::kTexture, bgr, in_area, whole);
    PixelFeatures features;
    features.compute(FeatureSet::kTexture, bgr, area, cv::Mat());
    const auto& names = feature_names(FeatureSet::kTexture);
    std::vector<float> got(names.size());
    for (int row = 0; row < area.height; ++row) {
      for (int col = 0; col < area.width; ++col) {
        features.at(row, col, got.data());
        const float* want = whole.ptr<float>((area.y + row) * bgr.cols + area.x + col);
        for (std::size_t i = 0; i < names.size(); ++i) {
          // Running window sums that start elsewhere round differently.
          EXPECT_NEAR(got[i], want[i], 1e-5 * std::max(1.0f, std::abs(want[i])))
              << names[i] << " at row " << row << ", column " << col << " of " << area;
        }
      }
    }
  }
}

TEST(PixelFeatures, MedianCountsOnlyTheCountedPixels) {
  cv::Mat luma(2, 4, CV_32F, cv::Scalar(200));
  luma.row(1) = 20.0f;
  cv::Mat counted(2, 4, CV_8UC1, cv::Scalar(0));
  counted.row(1) = 255;
  EXPECT_EQ(median_luminance(luma, counted), 20.0f);
  EXPECT_EQ(median_luminance(luma, cv::Mat()), 20.0f);  // the lower median of 4 x 20, 4 x 200
  EXPECT_EQ(median_luminance(cv::Mat(2, 2, CV_32F, cv::Scalar(0)), cv::Mat()), 1.0f);
}

// Lighting that scales every channel leaves the shading-invariant features alone, up to
// the 8-bit rounding of the darker image.
TEST(PixelFeatures, TextureIgnoresTheLightingOfTheImage) {
  const cv::Mat bright = test_image();
  cv::Mat dim, a, b;
  bright.convertTo(dim, CV_8UC3, 0.5);
  pixel_features(FeatureSet::kTexture, bright, cv::Mat(), a);
  pixel_features(FeatureSet::kTexture, dim, cv::Mat(), b);
  const auto& names = feature_names(FeatureSet::kTexture);
  for (int i = 0; i < a.cols; ++i) {
    const double mean = cv::mean(cv::abs(a.col(i) - b.col(i)))[0];
    const double scale = cv::mean(cv::abs(a.col(i)))[0];
    EXPECT_LT(mean, 0.1 * scale + 0.02) << names[i];
  }
}

TEST(PixelFeatures, ColourSetDescribesTheSmoothedColour) {
  const cv::Mat bgr(3, 3, CV_8UC3, cv::Scalar(100, 150, 200));
  cv::Mat features;
  pixel_features(FeatureSet::kColour, bgr, cv::Mat(), features);
  ASSERT_EQ(features.cols, 9);
  const float* f = features.ptr<float>(4);
  EXPECT_NEAR(f[5], 200.0f / 255.0f, 1e-5);                               // V
  EXPECT_NEAR(f[6], (2 * 150.0f - 200 - 100) / (100 + 150 + 200), 1e-5);  // exg
}

}  // namespace
}  // namespace tilth::segmentation
