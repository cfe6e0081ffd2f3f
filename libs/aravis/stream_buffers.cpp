#include "stream_buffers.h"

#include <algorithm>

#include "tilth/error.h"

namespace tilth::aravis {

// One buffer and the OpenCV reference count that tracks the cv::Mats sharing it.
struct StreamBuffers::Slot {
  explicit Slot(const cv::MatAllocator* allocator) : shared(allocator) {}
  ArvBuffer* buffer = nullptr;
  cv::UMatData shared;
  std::shared_ptr<StreamBuffers> lender;  // set while lent: keeps the stream alive
};

// Called by OpenCV when the last cv::Mat of a lent buffer is released. It never
// allocates: lent pixels are only ever wrapped.
class StreamBuffers::Allocator final : public cv::MatAllocator {
 public:
  cv::UMatData* allocate(int, const int*, int, void*, size_t*, cv::AccessFlag,
                         cv::UMatUsageFlags) const override {
    return nullptr;
  }
  bool allocate(cv::UMatData*, cv::AccessFlag, cv::UMatUsageFlags) const override { return false; }
  void deallocate(cv::UMatData* data) const override {
    auto* slot = static_cast<Slot*>(data->userdata);
    // Take the lender first: once the buffer is back, the slot may be lent again.
    std::shared_ptr<StreamBuffers> lender = std::move(slot->lender);
    lender->give_back(slot->buffer);
  }

  static const Allocator& instance() {
    static const Allocator allocator;
    return allocator;
  }
};

StreamBuffers::StreamBuffers(ArvStream* stream)
    : stream_(static_cast<ArvStream*>(g_object_ref(stream))) {}

std::shared_ptr<StreamBuffers> StreamBuffers::create(ArvStream* stream, std::size_t count,
                                                     std::size_t bytes) {
  std::shared_ptr<StreamBuffers> buffers(new StreamBuffers(stream));
  for (std::size_t i = 0; i < count; ++i) {
    auto slot = std::make_unique<Slot>(&Allocator::instance());
    slot->buffer = arv_buffer_new_full(bytes, nullptr, slot.get(), nullptr);
    arv_stream_push_buffer(stream, slot->buffer);  // the stream owns it until popped
    buffers->slots_.push_back(std::move(slot));
  }
  return buffers;
}

// The stream unrefs the buffers still in its queues; no buffer is lent (a lent one keeps
// this object alive).
StreamBuffers::~StreamBuffers() { g_object_unref(stream_); }

void StreamBuffers::lend(ArvBuffer* buffer, std::span<cv::Mat* const> pixels) {
  auto* slot = static_cast<Slot*>(const_cast<void*>(arv_buffer_get_user_data(buffer)));
  const bool owned = std::any_of(pixels.begin(), pixels.end(),
                                 [](const cv::Mat* mat) { return mat->u != nullptr; });
  if (slot == nullptr || owned || pixels.empty()) {
    give_back(buffer);
    throw Error(
        "internal: lending a buffer that is not this stream's, to no pixels, or to "
        "pixels already owned");
  }
  std::size_t size = 0;
  const void* data = arv_buffer_get_data(buffer, &size);
  cv::UMatData& shared = slot->shared;
  shared.data = shared.origdata = static_cast<uchar*>(const_cast<void*>(data));
  shared.size = size;
  shared.userdata = slot;
  shared.refcount = static_cast<int>(pixels.size());
  shared.urefcount = 0;
  slot->lender = shared_from_this();
  for (cv::Mat* mat : pixels) mat->u = &shared;
}

void StreamBuffers::give_back(ArvBuffer* buffer) { arv_stream_push_buffer(stream_, buffer); }

}  // namespace tilth::aravis
