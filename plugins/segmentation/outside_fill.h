// Fills what lies outside the segmented area of the images an output hands out from its
// pools, once per buffer: a buffer kept from one frame to the next (reuse_or_create) is
// filled again only when the area moved. Nothing writes a message's images but the stage
// that emits it, so a kept buffer still holds what this filled.
#pragma once

#include <cstdint>
#include <mutex>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace tilth::segmentation {

class OutsideFill {
 public:
  // Sets the pixels of `image` outside `area` to `value`, unless its buffer is the one it
  // had before reuse_or_create (`before`: its data then) and was filled for `area` here.
  void fill(cv::Mat& image, const std::uint8_t* before, const cv::Rect& area, double value);

 private:
  // More than the pools' buffers: an entry evicted early only costs a fill.
  static constexpr std::size_t kRemembered = 64;

  std::mutex mutex_;  // stages that run frames in parallel share their output
  std::vector<std::pair<const std::uint8_t*, cv::Rect>> filled_;  // oldest first
};

}  // namespace tilth::segmentation
