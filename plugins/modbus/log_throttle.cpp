#include "log_throttle.h"

namespace tilth::modbus {

LogThrottle::LogThrottle(Logger log, LogLevel level, std::chrono::milliseconds period)
    : log_(std::move(log)), level_(level), period_(period) {}

void LogThrottle::event(Clock::time_point now, std::string message) {
  flush(now);
  if (last_logged_ && now - *last_logged_ < period_) {
    ++held_back_;
    latest_ = std::move(message);
    return;
  }
  log(level_, log_.where(), message);
  last_logged_ = now;
}

void LogThrottle::flush(Clock::time_point now) {
  if (held_back_ > 0 && now >= *deadline()) summarize(now);
}

void LogThrottle::summarize(Clock::time_point now) {
  if (held_back_ == 0) return;
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(now - *last_logged_);
  log(level_, log_.where(),
      std::to_string(held_back_) + " more like it in the last " + std::to_string(seconds.count()) +
          " s; the latest: " + latest_);
  held_back_ = 0;
  latest_.clear();
  last_logged_ = now;
}

std::optional<LogThrottle::Clock::time_point> LogThrottle::deadline() const {
  if (held_back_ == 0) return std::nullopt;
  return *last_logged_ + period_;
}

}  // namespace tilth::modbus
