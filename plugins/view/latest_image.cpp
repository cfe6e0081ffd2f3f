#include "latest_image.h"

namespace tilth::view {

void LatestImage::publish(std::uint64_t frame_id, std::vector<unsigned char> jpeg) {
  auto bytes = std::make_shared<const std::vector<unsigned char>>(std::move(jpeg));
  {
    std::lock_guard lock(mutex_);
    latest_ = {latest_.generation + 1, frame_id, std::move(bytes)};
  }
  published_.notify_all();
}

LatestImage::Image LatestImage::newer_than(std::uint64_t after, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  const bool fresh =
      published_.wait_for(lock, timeout, [&] { return closed_ || latest_.generation > after; });
  if (!fresh || closed_) return {};
  return latest_;
}

void LatestImage::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  published_.notify_all();
}

}  // namespace tilth::view
