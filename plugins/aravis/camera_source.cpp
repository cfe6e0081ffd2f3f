#include "camera_source.h"

#include <chrono>

namespace tilth::aravis {
namespace {

std::int64_t host_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

CameraSource::CameraSource(CameraSettings settings, const StageContext& context)
    : node_(context.node), log_(context.log), session_(std::move(settings), context.log) {}

bool CameraSource::produce(Frame& frame) {
  PoppedBuffer buffer;
  if (!session_.next(buffer)) return false;
  std::string problem;
  if (buffer) {
    ArvBuffer* received = buffer.get();
    const auto device_ns = static_cast<std::int64_t>(arv_buffer_get_timestamp(received));
    frame.set_capture(arv_buffer_get_frame_id(received), device_ns,
                      static_cast<std::int64_t>(arv_buffer_get_system_timestamp(received)));
    try {
      convert(layout_of(received), buffer, session_.description(), device_ns, frame);
    } catch (const Error& error) {
      problem = "a frame of " + session_.description().label + " not passed on: " + error.what();
      if (problem != conversion_problem_) {
        log_.warning(problem + " (frame " + std::to_string(arv_buffer_get_frame_id(received)) +
                     "; logged again when the problem changes)");
      }
    }
  } else {
    frame.set_capture(0, 0, host_now_ns());
  }
  conversion_problem_ = problem;

  auto status = statuses_.acquire();
  session_.fill_status(*status);
  status->camera = node_;
  if (!problem.empty()) status->problem = problem;
  frame.set_output(kStatus, std::move(status));
  return true;
}

}  // namespace tilth::aravis
