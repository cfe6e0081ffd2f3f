// One camera: opened, configured from a stage's settings, and streaming into buffers
// allocated once. Closing it (the destructor) stops acquisition, which waits out the
// GigE Vision control timeouts (about 2.5 s) when the camera is gone: close it off the
// frame path.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>

#include <arv.h>

#include "aravis/gobject_ptr.h"
#include "camera_settings.h"
#include "camera_setup.h"
#include "software_trigger.h"
#include "stream_buffers.h"
#include "tilth/log.h"

namespace tilth::aravis {

class CameraConnection {
 public:
  // Called on Aravis's threads when a buffer is finished or the camera's control is lost.
  using Notify = std::function<void()>;

  // Throws tilth::Error when the camera cannot be found, opened or configured.
  CameraConnection(const CameraSettings& settings, const Logger& log, Notify notify);
  ~CameraConnection();
  CameraConnection(const CameraConnection&) = delete;
  CameraConnection& operator=(const CameraConnection&) = delete;

  const CameraDescription& description() const { return description_; }
  // A finished buffer, complete or not; empty when none is waiting.
  PoppedBuffer try_pop();
  bool control_lost() const { return events_->control_lost; }
  // How often the stream found no free buffer for a packet, since it started.
  std::uint64_t underruns() const;

 private:
  // What Aravis's threads call into. Shared with the stream and the signal handler, which
  // may outlive this connection (lent buffers keep the stream): closing detaches it.
  struct Events {
    std::mutex mutex;
    Notify notify;  // empty once detached
    std::atomic<bool> control_lost{false};
    int receive_nice = 0;
    Logger log{""};
    void fire();
    void detach();
  };
  static void on_stream_event(void* events, ArvStreamCallbackType type, ArvBuffer* buffer);
  static void on_control_lost(ArvDevice* device, void* events);
  static void release_events(void* events, GClosure* closure);
  void close();

  std::shared_ptr<Events> events_ = std::make_shared<Events>();
  GObjectPtr<ArvCamera> camera_;
  CameraDescription description_;
  GObjectPtr<ArvStream> stream_;
  std::shared_ptr<StreamBuffers> buffers_;
  gulong control_lost_handler_ = 0;
  bool acquiring_ = false;
  std::unique_ptr<SoftwareTrigger> trigger_;  // while acquiring, with trigger_mode host_clock
};

}  // namespace tilth::aravis
