#include "camera_connection.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "aravis/device_list.h"

namespace tilth::aravis {
namespace {

std::string text_or(const char* text, const char* fallback) {
  return text != nullptr && *text != '\0' ? text : fallback;
}

}  // namespace

CameraConnection::CameraConnection(const CameraSettings& settings, const Logger& log,
                                   Notify notify) {
  events_->notify = std::move(notify);
  events_->receive_nice = settings.receive_nice;
  events_->log = log;
  const std::string address = resolve_camera_address(settings.camera);
  GErrorSlot error;
  camera_.reset(arv_camera_new(address.c_str(), error.out()));
  error.check("opening the GigE Vision camera at " + address);
  if (!arv_camera_is_gv_device(camera_.get())) {
    throw Error("the camera at " + address + " is not a GigE Vision device");
  }
  const std::string label =
      text_or(arv_camera_get_vendor_name(camera_.get(), nullptr), "?") + " " +
      text_or(arv_camera_get_model_name(camera_.get(), nullptr), "?") + " (serial " +
      text_or(arv_camera_get_device_serial_number(camera_.get(), nullptr), "?") + ") at " + address;
  try {
    description_ = configure_camera(camera_.get(), label, settings, log);
    arv_camera_gv_set_stream_options(
        camera_.get(), settings.packet_socket ? ARV_GV_STREAM_OPTION_NONE
                                              : ARV_GV_STREAM_OPTION_PACKET_SOCKET_DISABLED);
    stream_.reset(arv_camera_create_stream_full(
        camera_.get(), &CameraConnection::on_stream_event, new std::shared_ptr<Events>(events_),
        [](void* events) { delete static_cast<std::shared_ptr<Events>*>(events); }, error.out()));
    error.check("creating the stream of camera " + label);
    // Room for two frames, and never less than 1 MiB: the kernel charges each packet far
    // more than its size, so a buffer of one small frame's size (Aravis's "auto") drops
    // most of its packets.
    const std::size_t socket_bytes = std::max<std::size_t>(2 * description_.payload_bytes, 1 << 20);
    g_object_set(stream_.get(), "packet-resend",
                 settings.packet_resend ? ARV_GV_STREAM_PACKET_RESEND_ALWAYS
                                        : ARV_GV_STREAM_PACKET_RESEND_NEVER,
                 "socket-buffer", ARV_GV_STREAM_SOCKET_BUFFER_FIXED, "socket-buffer-size",
                 static_cast<gint>(socket_bytes), nullptr);
    buffers_ = StreamBuffers::create(stream_.get(), settings.buffers, description_.payload_bytes);
    control_lost_handler_ = g_signal_connect_data(
        arv_camera_get_device(camera_.get()), "control-lost",
        G_CALLBACK(&CameraConnection::on_control_lost), new std::shared_ptr<Events>(events_),
        &CameraConnection::release_events, GConnectFlags{});
    arv_camera_start_acquisition(camera_.get(), error.out());
    error.check("starting acquisition on camera " + label);
    acquiring_ = true;
    if (settings.software_trigger_hz > 0.0) {
      trigger_ = std::make_unique<SoftwareTrigger>(camera_.get(), settings.software_trigger_hz,
                                                   label, settings.receive_nice, log);
    }
  } catch (...) {
    close();
    throw;
  }
  log.info("streaming from " + label + ": " + description_.pixel_format + ", " +
           std::to_string(description_.payload_bytes) + " bytes per frame, " +
           std::to_string(settings.buffers) + " buffers, packet socket " +
           (settings.packet_socket ? "on" : "off"));
}

CameraConnection::~CameraConnection() { close(); }

void CameraConnection::close() {
  events_->detach();
  if (control_lost_handler_ != 0) {
    g_signal_handler_disconnect(arv_camera_get_device(camera_.get()), control_lost_handler_);
    control_lost_handler_ = 0;
  }
  trigger_.reset();
  if (acquiring_) {
    arv_camera_stop_acquisition(camera_.get(), nullptr);  // fails when the camera is gone
    acquiring_ = false;
  }
  // Lent buffers keep the stream, and through it the device, until they come back: let go
  // of the camera's control now, so that it can be opened again meanwhile.
  if (camera_)
    arv_gv_device_leave_control(ARV_GV_DEVICE(arv_camera_get_device(camera_.get())), nullptr);
  buffers_.reset();
  stream_.reset();
  camera_.reset();
}

PoppedBuffer CameraConnection::try_pop() {
  ArvBuffer* buffer = arv_stream_try_pop_buffer(stream_.get());
  if (buffer == nullptr) return {};
  return PoppedBuffer(buffers_, buffer);
}

std::uint64_t CameraConnection::underruns() const {
  guint64 completed = 0;
  guint64 failures = 0;
  guint64 underruns = 0;
  arv_stream_get_statistics(stream_.get(), &completed, &failures, &underruns);
  return underruns;
}

void CameraConnection::Events::fire() {
  std::lock_guard lock(mutex);
  if (notify) notify();
}

void CameraConnection::Events::detach() {
  std::lock_guard lock(mutex);
  notify = nullptr;
}

void CameraConnection::on_stream_event(void* events, ArvStreamCallbackType type, ArvBuffer*) {
  Events& shared = **static_cast<std::shared_ptr<Events>*>(events);
  if (type == ARV_STREAM_CALLBACK_TYPE_BUFFER_DONE) {
    shared.fire();
  } else if (type == ARV_STREAM_CALLBACK_TYPE_INIT && shared.receive_nice != 0) {
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), shared.receive_nice) != 0) {
      shared.log.warning("cannot give the stream's receiving thread nice level " +
                         std::to_string(shared.receive_nice) + ": " + std::strerror(errno) +
                         " (needs CAP_SYS_NICE; receive_nice 0 keeps the process's)");
    }
  }
}

void CameraConnection::on_control_lost(ArvDevice*, void* events) {
  auto& shared = *static_cast<std::shared_ptr<Events>*>(events);
  shared->control_lost = true;
  shared->fire();
}

void CameraConnection::release_events(void* events, GClosure*) {
  delete static_cast<std::shared_ptr<Events>*>(events);
}

}  // namespace tilth::aravis
