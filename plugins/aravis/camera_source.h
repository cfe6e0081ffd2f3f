// What the two camera stages share: a CameraSession, the capture identity of each frame
// (the GigE Vision block id, the device timestamp and the host receive time), the status
// output on every frame, and frames without an image while the camera is lost. A stage
// adds the conversion of a received buffer into its image message.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "aravis/camera_session.h"
#include "aravis/frame_layout.h"
#include "aravis/recycling_allocator.h"
#include "tilth/message_pool.h"
#include "tilth/messages/camera_status.h"
#include "tilth/stage.h"
#include "tilth/stage_context.h"

namespace tilth::aravis {

class CameraSource : public Source {
 public:
  enum Port { kImage = 0, kStatus = 1 };

  CameraSource(CameraSettings settings, const StageContext& context);

  bool produce(Frame& frame) final;
  void interrupt() final { session_.interrupt(); }

 protected:
  // Sets the image outputs of `frame` (kImage, and any the stage adds after kStatus) from
  // one complete buffer, their pixels lent from `buffer` (no copy). Throws tilth::Error,
  // having set none, when the buffer holds nothing this stage takes.
  virtual void convert(const BufferLayout& layout, PoppedBuffer& buffer,
                       const CameraDescription& camera, std::int64_t device_timestamp_ns,
                       Frame& frame) = 0;

  // A message for one frame, from memory this source recycles.
  template <class T>
  std::shared_ptr<T> make_message() {
    return std::allocate_shared<T>(RecyclingAllocator<T>(blocks_));
  }

 private:
  const std::string node_;
  const Logger log_;
  std::shared_ptr<RecycledBlocks> blocks_ = std::make_shared<RecycledBlocks>();
  MessagePool<CameraStatus> statuses_;
  std::string conversion_problem_;
  CameraSession session_;
};

}  // namespace tilth::aravis
