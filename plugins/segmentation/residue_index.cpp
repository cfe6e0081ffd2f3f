#include "residue_index.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "box_sums.h"
#include "otsu.h"
#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

constexpr int kBins = 256;
// A normal distribution's standard deviation per median absolute deviation.
constexpr float kSigmaPerMad = 1.4826f;

// Histogram range (values outside are counted in the end bins), which side residue is
// on, the absolute boundary for frames of one material, and the least gap between
// Otsu's class means that still counts as two materials. docs/segmentation-variants.md derives
// them from the reference colours and the simulator.
struct IndexInfo {
  const char* name;
  float low;
  float high;
  bool residue_above;
  float boundary;
  float min_gap;
};

constexpr std::array<IndexInfo, 4> kIndices{{
    {"exg", -0.5f, 0.5f, true, 0.02f, 0.05f},
    {"exr", -0.5f, 1.0f, false, 0.27f, 0.035f},
    {"exgr", -1.5f, 0.5f, true, -0.19f, 0.1f},
    {"hue", -60.0f, 120.0f, true, 36.0f, 9.0f},
}};

const IndexInfo& info(ColorIndex index) { return kIndices[static_cast<int>(index)]; }

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// One pixel's index from its (summed) B, G, R; NaN for black (0 / 0 in the ratios, which
// thus need no branch and vectorise), and for grey in the hue index.
template <ColorIndex kIndex>
float index_of(float b, float g, float r) {
  if constexpr (kIndex == ColorIndex::kExg) return (2 * g - r - b) / (b + g + r);
  if constexpr (kIndex == ColorIndex::kExr) return (1.4f * r - g) / (b + g + r);
  if constexpr (kIndex == ColorIndex::kExgr) return (3 * g - 2.4f * r - b) / (b + g + r);
  // HSV hue in degrees, with red-magenta (above 300) taken as negative so that the
  // reds and browns of soil stay next to the yellows of straw: -60 .. 300.
  const float high = std::max({b, g, r});
  const float delta = high - std::min({b, g, r});
  if (delta <= 0) return kNaN;
  if (high == r) return 60 * (g - b) / delta;
  if (high == g) return 60 * ((b - r) / delta + 2);
  return 60 * ((r - g) / delta + 4);
}

// Writes each pixel's index and counts the trusted ones into the histogram. The channels
// are first taken apart into rows of floats, so that the index is computed a vector at a
// time (the same operations in the same order: the same floats). Neighbouring pixels
// often fall in one bin: counting them in turn into four histograms keeps each count from
// waiting for the one before.
template <ColorIndex kIndex>
void index_and_histogram(const cv::Mat& summed, const cv::Mat& untrusted, const IndexInfo& range,
                         cv::Mat& index, std::array<double, kBins>& histogram) {
  constexpr int kLanes = 4;
  const float bins_per_unit = kBins / (range.high - range.low);
  std::array<std::array<std::uint32_t, kBins + 1>, kLanes> counts{};
  thread_local std::vector<float> blue, green, red;
  thread_local std::vector<int> bins;
  for (auto* channel : {&blue, &green, &red}) channel->resize(summed.cols);
  const int cols = summed.cols;  // read once: the bins' writes could alias it
  bins.resize(cols);
  int* const bin = bins.data();
  float* const b = blue.data();
  float* const g = green.data();
  float* const r = red.data();
  for (int row = 0; row < summed.rows; ++row) {
    const auto* in = summed.ptr<std::uint16_t>(row);
    const auto* skip = untrusted.ptr<std::uint8_t>(row);
    auto* out = index.ptr<float>(row);
    for (int col = 0; col < summed.cols; ++col) {
      b[col] = in[3 * col];
      g[col] = in[3 * col + 1];
      r[col] = in[3 * col + 2];
    }
    for (int col = 0; col < summed.cols; ++col) out[col] = index_of<kIndex>(b[col], g[col], r[col]);
    // Each pixel's bin, a vector at a time; kBins (counted, then left out) where the
    // colour is untrusted or black.
    for (int col = 0; col < cols; ++col) {
      const bool black = out[col] != out[col];  // NaN
      const float value = black ? range.low : out[col];
      const float scaled = std::min(std::max((value - range.low) * bins_per_unit, 0.0f),
                                    static_cast<float>(kBins - 1));
      const int counted = (skip[col] == 0) & !black;
      bin[col] = counted ? static_cast<int>(scaled) : kBins;
    }
    for (int col = 0; col < cols; ++col) ++counts[col % kLanes][bin[col]];
  }
  for (const auto& lane : counts) {
    for (int bin = 0; bin < kBins; ++bin) histogram[bin] += lane[bin];
  }
}

// Whether the noise of the soil's index is at most `limit`: the robust standard deviation
// (1.4826 MAD / sqrt 2) of the differences between trusted soil pixels 2r+1 columns apart
// (boxes that do not overlap), on every fourth row; at most `limit` when at least half of
// those differences are within limit * sqrt 2 / 1.4826. The soil's, because soil is what
// noise takes away (one cue is enough for residue), and it is often the darker material,
// whose index varies more; pairs on the soil side of the threshold only, since straw in
// the light may be quiet where soil in its shadow is not.
bool soil_quieter_than(const cv::Mat& index, const cv::Mat& untrusted, const IndexInfo& range,
                       float threshold, int smoothing_px, float limit) {
  const int apart = 2 * smoothing_px + 1;
  const float within = limit * std::numbers::sqrt2_v<float> / kSigmaPerMad;
  const float sign = range.residue_above ? 1.0f : -1.0f;  // soil: sign * index < sign * threshold
  const float soil_below = sign * threshold;
  int pairs = 0;
  int close = 0;
  for (int row = 0; row < index.rows; row += 4) {
    const auto* value = index.ptr<float>(row);
    const auto* skip = untrusted.ptr<std::uint8_t>(row);
    for (int col = 0; col + apart < index.cols; ++col) {
      const float a = value[col], b = value[col + apart];
      // NaN compares false: no colour, no pair.
      const int soil = ((skip[col] | skip[col + apart]) == 0) & (sign * a < soil_below) &
                       (sign * b < soil_below);
      pairs += soil;
      close += soil & (std::abs(b - a) <= within);
    }
  }
  return 2 * close >= pairs;
}

}  // namespace

ColorIndex parse_color_index(const std::string& name) {
  for (std::size_t i = 0; i < kIndices.size(); ++i) {
    if (name == kIndices[i].name) return static_cast<ColorIndex>(i);
  }
  throw Error("parameter 'index': expected one of 'exg', 'exr', 'exgr', 'hue', got '" + name + "'");
}

std::vector<std::string> color_index_names() {
  std::vector<std::string> names;
  for (const auto& index : kIndices) names.emplace_back(index.name);
  return names;
}

ResidueIndex::ResidueIndex(ColorIndex index, int smoothing_px, int max_smoothing_px)
    : index_(index),
      smoothing_px_(smoothing_px),
      max_smoothing_px_(std::max(smoothing_px, max_smoothing_px)) {}

IndexSplit ResidueIndex::classify(const cv::Mat& bgr, const cv::Mat& untrusted,
                                  cv::Mat& residue) const {
  thread_local cv::Mat index;
  return classify(bgr, untrusted, residue, index);
}

IndexSplit ResidueIndex::classify(const cv::Mat& bgr, const cv::Mat& untrusted, cv::Mat& residue,
                                  cv::Mat& index) const {
  const IndexInfo& range = info(index_);
  IndexSplit split = split_at(smoothing_px_, bgr, untrusted, index);
  while (split.smoothing_px < max_smoothing_px_ &&
         !soil_quieter_than(index, untrusted, range, split.threshold, split.smoothing_px,
                            kNoiseShareOfGap * range.min_gap)) {
    split = split_at(split.smoothing_px + 1, bgr, untrusted, index);
  }
  // NaN compares false: no colour, no residue.
  cv::compare(index, split.threshold, residue, range.residue_above ? cv::CMP_GE : cv::CMP_LT);
  return split;
}

IndexSplit ResidueIndex::split_at(int smoothing_px, const cv::Mat& bgr, const cv::Mat& untrusted,
                                  cv::Mat& index) const {
  const IndexInfo& range = info(index_);
  const float bins_per_unit = kBins / (range.high - range.low);

  // Unnormalised: an index is a ratio of channels, so the box's sum will do.
  thread_local cv::Mat summed;
  box_sums(bgr, smoothing_px, summed);
  index.create(bgr.size(), CV_32FC1);
  std::array<double, kBins> histogram{};
  switch (index_) {
    case ColorIndex::kExg:
      index_and_histogram<ColorIndex::kExg>(summed, untrusted, range, index, histogram);
      break;
    case ColorIndex::kExr:
      index_and_histogram<ColorIndex::kExr>(summed, untrusted, range, index, histogram);
      break;
    case ColorIndex::kExgr:
      index_and_histogram<ColorIndex::kExgr>(summed, untrusted, range, index, histogram);
      break;
    case ColorIndex::kHue:
      index_and_histogram<ColorIndex::kHue>(summed, untrusted, range, index, histogram);
      break;
  }

  IndexSplit split;
  split.threshold = range.boundary;
  split.min_gap = range.min_gap;
  split.smoothing_px = smoothing_px;
  split.residue_above = range.residue_above;
  if (const auto otsu = otsu_split(histogram)) {
    split.class_gap = static_cast<float>(otsu->upper_mean - otsu->lower_mean) / bins_per_unit;
    if (split.class_gap >= range.min_gap) {
      split.two_classes = true;
      split.threshold = range.low + static_cast<float>(otsu->threshold_bin) / bins_per_unit;
    }
  }
  return split;
}

// From a histogram of a thousand bins over the index's range (values outside it in the
// end bins) of every second pixel of every second row (the index is that of a box at
// least 3x3): the median is the middle of its bin, and the median absolute deviation the
// fewest bins around the median's that hold half of the pixels.
std::optional<IndexSpread> ResidueIndex::spread(const cv::Mat& index, const cv::Mat& among) const {
  constexpr int kSpreadBins = 1000;
  constexpr int kSpreadStepPx = 2;
  const IndexInfo& range = info(index_);
  const float bins_per_unit = kSpreadBins / (range.high - range.low);
  std::array<int, kSpreadBins> histogram{};
  int count = 0;
  for (int row = 0; row < index.rows; row += kSpreadStepPx) {
    const auto* value = index.ptr<float>(row);
    const auto* marked = among.ptr<std::uint8_t>(row);
    for (int col = 0; col < index.cols; col += kSpreadStepPx) {
      if (marked[col] == 0 || value[col] != value[col]) continue;  // NaN: no colour
      const float scaled = (value[col] - range.low) * bins_per_unit;
      ++histogram[static_cast<std::size_t>(std::clamp(scaled, 0.0f, kSpreadBins - 1.0f))];
      ++count;
    }
  }
  if (count < kMinSpreadPixels) return std::nullopt;
  int middle = 0;
  for (int below = 0; below + histogram[middle] <= count / 2; ++middle) below += histogram[middle];
  int half_width = 0;
  for (int within = histogram[middle]; 2 * within < count; ++half_width) {
    const int left = middle - half_width - 1, right = middle + half_width + 1;
    within += (left >= 0 ? histogram[left] : 0) + (right < kSpreadBins ? histogram[right] : 0);
  }
  return IndexSpread{range.low + (static_cast<float>(middle) + 0.5f) / bins_per_unit,
                     kSigmaPerMad * static_cast<float>(half_width) / bins_per_unit};
}

std::string IndexSplit::text() const {
  char text[64];
  std::snprintf(text, sizeof text, "class gap %.3g, two materials from %.3g", class_gap, min_gap);
  return text;
}

ParamSpec max_smoothing_px_param() {
  return ParamSpec::integer("max_smoothing_px", 3)
      .range(0, 3)
      .in_unit("px")
      .describe(
          "noisier colours (gain in low light) are averaged over boxes up to (2r+1)^2 until "
          "the index's noise is under 0.6 of its least gap between materials; at most "
          "smoothing_px: always smoothing_px");
}

ParamSpec color_index_param() {
  return ParamSpec::choice("index", color_index_names(), "exg")
      .describe(
          "exg = 2g-r-b, exr = 1.4r-g (chromaticities r, g, b), exgr = exg-exr, or hue (deg)");
}

}  // namespace tilth::segmentation
