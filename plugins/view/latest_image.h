// The newest rendered view image, handed from the renderer to every viewer: each waits
// for one newer than the last it got, so a slow viewer skips images and never queues them.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace tilth::view {

class LatestImage {
 public:
  struct Image {
    std::uint64_t generation = 0;  // 1 for the first image, counting up
    std::uint64_t frame_id = 0;
    std::shared_ptr<const std::vector<unsigned char>> jpeg;
  };

  void publish(std::uint64_t frame_id, std::vector<unsigned char> jpeg);
  // The newest image when its generation is after `after`, waiting up to `timeout` for
  // one; an image with no bytes when none came or close() was called.
  Image newer_than(std::uint64_t after, std::chrono::milliseconds timeout);
  // Wakes every waiter for good: the server is stopping.
  void close();

 private:
  std::mutex mutex_;
  std::condition_variable published_;
  Image latest_;
  bool closed_ = false;
};

}  // namespace tilth::view
