#include "outside_fill.h"

#include <algorithm>

namespace tilth::segmentation {

void OutsideFill::fill(cv::Mat& image, const std::uint8_t* before, const cv::Rect& area,
                       double value) {
  const std::pair<const std::uint8_t*, cv::Rect> entry(image.data, area);
  {
    std::lock_guard lock(mutex_);
    const auto found = std::find_if(filled_.begin(), filled_.end(),
                                    [&](const auto& filled) { return filled.first == image.data; });
    if (found != filled_.end()) {
      if (image.data == before && found->second == area) return;
      filled_.erase(found);
    }
    if (filled_.size() == kRemembered) filled_.erase(filled_.begin());
    filled_.push_back(entry);
  }
  for (const cv::Rect& band :
       {cv::Rect(0, 0, image.cols, area.y),
        cv::Rect(0, area.br().y, image.cols, image.rows - area.br().y),
        cv::Rect(0, area.y, area.x, area.height),
        cv::Rect(area.br().x, area.y, image.cols - area.br().x, area.height)}) {
    if (!band.empty()) image(band).setTo(value);
  }
}

}  // namespace tilth::segmentation
