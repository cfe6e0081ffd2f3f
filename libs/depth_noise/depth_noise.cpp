#include "depth_noise/depth_noise.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace tilth {
namespace {

constexpr int kApart = 2;
constexpr int kRowStep = 4;
constexpr int kMinPairs = 100;
// The median absolute difference of a standard deviation sigma.
constexpr float kDifferencePerSigma = std::numbers::sqrt2_v<float> / 1.4826f;

// A depth that is a measurement: neither NaN, nor infinite, nor <= 0.
bool measured(float depth_mm) { return std::isfinite(depth_mm) && depth_mm > 0; }

// Calls `pair(a, b)` for every pair of depths two columns apart on the sampled rows.
template <class Pair>
void for_each_pair(const cv::Mat& depth_mm, const cv::Rect& area, Pair&& pair) {
  for (int row = area.y; row < area.y + area.height; row += kRowStep) {
    const auto* depth = depth_mm.ptr<float>(row);
    for (int col = area.x; col + kApart < area.x + area.width; ++col) {
      pair(depth[col], depth[col + kApart]);
    }
  }
}

}  // namespace

float depth_noise_mm(const cv::Mat& depth_mm, const cv::Rect& area, float at_least_mm) {
  int pairs = 0;
  int within = 0;
  const float within_mm = at_least_mm * kDifferencePerSigma;
  for_each_pair(depth_mm, area, [&](float a, float b) {
    const int counted = measured(a) & measured(b);
    pairs += counted;
    within += counted & (std::abs(b - a) <= within_mm);
  });
  if (pairs < kMinPairs) return 0.0f;
  if (2 * within >= pairs) return at_least_mm;

  // The median from a histogram of 0.1 mm bins; the last holds every larger difference.
  constexpr float kBinsPerMm = 10.0f;
  std::array<int, 1000> counts{};
  constexpr auto kLastBin = static_cast<float>(counts.size() - 1);
  for_each_pair(depth_mm, area, [&](float a, float b) {
    if (!(measured(a) && measured(b))) return;
    ++counts[static_cast<std::size_t>(std::min(std::abs(b - a) * kBinsPerMm, kLastBin))];
  });
  int below = 0;
  std::size_t median_bin = 0;
  while (2 * (below + counts[median_bin]) < pairs) below += counts[median_bin++];
  const float median_mm = (static_cast<float>(median_bin) + 0.5f) / kBinsPerMm;
  return std::max(at_least_mm, median_mm / kDifferencePerSigma);
}

}  // namespace tilth
