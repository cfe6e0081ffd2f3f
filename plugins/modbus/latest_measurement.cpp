#include "latest_measurement.h"

#include <algorithm>

namespace tilth::modbus {

void LatestMeasurement::update(std::uint64_t frame_id, const GroundDistance& distance,
                               Clock::time_point arrived, Clock::duration capture_age) {
  // A held distance is as old as the frame it was measured in.
  const auto held_for =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double, std::milli>(
          distance.held ? std::max(distance.held_ms, 0.0) : 0.0));
  Measurement measurement{frame_id,
                          distance.valid,
                          distance.valid && distance.held,
                          distance.valid ? InvalidCause::kNone : distance.cause,
                          distance.distance_mm,
                          distance.soil_fraction,
                          distance.confidence,
                          arrived,
                          std::max(capture_age, Clock::duration::zero()) + held_for};
  std::lock_guard lock(mutex_);
  measurement_ = measurement;
  last_frame_ = arrived;
  last_frame_missing_ = false;
}

void LatestMeasurement::update_missing(Clock::time_point arrived) {
  std::lock_guard lock(mutex_);
  last_frame_ = arrived;
  last_frame_missing_ = true;
}

void LatestMeasurement::update_cameras(bool streaming) {
  std::lock_guard lock(mutex_);
  cameras_streaming_ = streaming;
}

RegisterValues LatestMeasurement::values_at(Clock::time_point now) const {
  std::lock_guard lock(mutex_);
  RegisterValues values;
  values.camera_ok = last_frame_ && now - *last_frame_ <= stale_timeout_ && cameras_streaming_;
  values.pipeline_error = last_frame_missing_ && cameras_streaming_;
  if (!measurement_) {
    values.stale = true;
    values.age = std::chrono::milliseconds::max();  // never: saturates
    return values;
  }
  const auto since_arrival = now - measurement_->arrived;
  // In whole milliseconds, as the age shows it: a stale block's age is past the timeout.
  values.stale =
      std::chrono::duration_cast<std::chrono::milliseconds>(since_arrival) > stale_timeout_;
  values.valid = measurement_->valid && !values.stale && !last_frame_missing_;
  values.held = values.valid && measurement_->held;
  values.cause = measurement_->cause;
  values.distance_mm = measurement_->distance_mm;
  values.soil_fraction = measurement_->soil_fraction;
  values.confidence = measurement_->confidence;
  values.frame_id = measurement_->frame_id;
  values.age = std::chrono::duration_cast<std::chrono::milliseconds>(
      measurement_->capture_age + std::max(since_arrival, Clock::duration::zero()));
  return values;
}

}  // namespace tilth::modbus
