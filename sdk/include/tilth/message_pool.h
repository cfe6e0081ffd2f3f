// Reuses a stage's output messages, and the images in them, once no one else holds
// them, so that a stage in steady state allocates nothing per frame.
//
//   auto depth = pool_.acquire();                 // std::shared_ptr<DepthImage>
//   reuse_or_create(depth->mm, rows, cols, CV_32FC1);
//   ... fill depth->mm ...
//   frame.set_output(0, depth);
//
// Invariant: a message is handed out again only when the pool holds its last
// reference; an image buffer is written again only when the message holds its last
// reference (a sink that kept a cv::Mat header keeps its pixels).
#pragma once

#include <atomic>
#include <memory>
#include <mutex>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace tilth {

template <class T>
class MessagePool {
 public:
  explicit MessagePool(std::size_t capacity = 16) : capacity_(capacity) {}

  // A message no one else holds (its previous contents are still in it), or a new one.
  std::shared_ptr<T> acquire() {
    std::lock_guard lock(mutex_);
    for (auto& message : messages_) {
      if (message.use_count() == 1) {
        // Pairs with the release in the last holder's reference drop.
        std::atomic_thread_fence(std::memory_order_acquire);
        return message;
      }
    }
    auto message = std::make_shared<T>();
    if (messages_.size() < capacity_) messages_.push_back(message);
    return message;
  }

  std::size_t size() const {
    std::lock_guard lock(mutex_);
    return messages_.size();
  }

 private:
  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::vector<std::shared_ptr<T>> messages_;
};

// Makes `image` rows x cols of `type`, keeping its buffer when it has that shape and no
// other cv::Mat shares it, and allocating a new one otherwise.
void reuse_or_create(cv::Mat& image, int rows, int cols, int type);

}  // namespace tilth
