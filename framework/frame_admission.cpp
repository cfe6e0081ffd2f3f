#include "framework/frame_admission.h"

#include <algorithm>

namespace tilth {

FrameAdmission::FrameAdmission(std::size_t sources, std::size_t max_in_flight, FullPolicy policy,
                               Admit admit, std::optional<std::uint64_t> frame_limit)
    : max_in_flight_(max_in_flight),
      policy_(policy),
      admit_(std::move(admit)),
      frame_limit_(frame_limit),
      waiting_(sources),
      ended_(sources, false) {
  if (frame_limit_ && *frame_limit_ == 0) closed_ = true;
}

bool FrameAdmission::offer(std::size_t source, std::shared_ptr<Bundle> bundle) {
  Batch batch;
  {
    std::unique_lock lock(mutex_);
    if (policy_ == FullPolicy::kBlock) {
      changed_.wait(lock, [&] { return closed_ || waiting_[source] == nullptr; });
    }
    if (closed_) return false;
    if (waiting_[source] != nullptr) ++dropped_;
    waiting_[source] = std::move(bundle);
    batch = take_admissible_locked();
  }
  admit_all(std::move(batch));
  return true;
}

void FrameAdmission::end_of_stream(std::size_t source) {
  std::lock_guard lock(mutex_);
  ended_[source] = true;
  if (waiting_[source] == nullptr) closed_ = true;
  changed_.notify_all();
}

void FrameAdmission::complete() {
  Batch batch;
  {
    std::lock_guard lock(mutex_);
    --in_flight_;
    batch = take_admissible_locked();
    changed_.notify_all();
  }
  admit_all(std::move(batch));
}

void FrameAdmission::close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  std::fill(waiting_.begin(), waiting_.end(), nullptr);
  changed_.notify_all();
}

void FrameAdmission::wait_until_drained() {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return closed_ && in_flight_ == 0; });
}

FrameAdmission::Batch FrameAdmission::take_admissible_locked() {
  Batch batch;
  while (
      !closed_ && in_flight_ < max_in_flight_ &&
      std::all_of(waiting_.begin(), waiting_.end(), [](const auto& b) { return b != nullptr; })) {
    std::vector<std::shared_ptr<Bundle>> frame;
    for (std::size_t s = 0; s < waiting_.size(); ++s) {
      frame.push_back(std::move(waiting_[s]));
      waiting_[s] = nullptr;
      if (ended_[s]) closed_ = true;
    }
    batch.emplace_back(next_sequence_++, std::move(frame));
    ++in_flight_;
    if (frame_limit_ && next_sequence_ >= *frame_limit_) closed_ = true;
  }
  if (!batch.empty()) changed_.notify_all();
  return batch;
}

void FrameAdmission::admit_all(Batch batch) {
  for (auto& [sequence, bundles] : batch) admit_(sequence, std::move(bundles));
}

std::uint64_t FrameAdmission::admitted() const {
  std::lock_guard lock(mutex_);
  return next_sequence_;
}

std::uint64_t FrameAdmission::dropped() const {
  std::lock_guard lock(mutex_);
  return dropped_;
}

std::uint64_t FrameAdmission::in_flight() const {
  std::lock_guard lock(mutex_);
  return in_flight_;
}

}  // namespace tilth
