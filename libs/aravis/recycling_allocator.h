// An allocator for std::allocate_shared that keeps freed blocks and hands them out
// again, so that a source making one message per frame stops allocating once there are
// as many blocks as messages alive at once. A message made this way is destroyed, and
// its images released, as soon as its last holder lets go (unlike tilth::MessagePool,
// whose messages keep their images until they are reused).
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <new>
#include <vector>

namespace tilth::aravis {

class RecycledBlocks {
 public:
  RecycledBlocks() = default;
  RecycledBlocks(const RecycledBlocks&) = delete;
  RecycledBlocks& operator=(const RecycledBlocks&) = delete;
  ~RecycledBlocks() {
    for (void* block : free_) ::operator delete(block);
  }

  // Blocks of the first size asked for are recycled; any other size is plain new/delete.
  void* take(std::size_t bytes) {
    {
      std::lock_guard lock(mutex_);
      if (block_bytes_ == 0) block_bytes_ = bytes;
      if (bytes == block_bytes_ && !free_.empty()) {
        void* block = free_.back();
        free_.pop_back();
        return block;
      }
    }
    return ::operator new(bytes);
  }

  void give(void* block, std::size_t bytes) {
    {
      std::lock_guard lock(mutex_);
      if (bytes == block_bytes_) {
        free_.push_back(block);  // within the capacity reached before: no allocation
        return;
      }
    }
    ::operator delete(block);
  }

 private:
  std::mutex mutex_;
  std::size_t block_bytes_ = 0;
  std::vector<void*> free_;
};

template <class T>
class RecyclingAllocator {
 public:
  using value_type = T;

  explicit RecyclingAllocator(std::shared_ptr<RecycledBlocks> blocks)
      : blocks_(std::move(blocks)) {}
  template <class U>
  RecyclingAllocator(const RecyclingAllocator<U>& other) : blocks_(other.blocks()) {}

  T* allocate(std::size_t n) { return static_cast<T*>(blocks_->take(n * sizeof(T))); }
  void deallocate(T* pointer, std::size_t n) { blocks_->give(pointer, n * sizeof(T)); }

  const std::shared_ptr<RecycledBlocks>& blocks() const { return blocks_; }
  template <class U>
  bool operator==(const RecyclingAllocator<U>& other) const {
    return blocks_ == other.blocks();
  }

 private:
  std::shared_ptr<RecycledBlocks> blocks_;  // held by every block's control block too
};

}  // namespace tilth::aravis
