// Log lines for an event that may come in floods (a refused connection, an idle client
// closed): the first in a period is logged as it happens, the others in that period
// are counted and summed up in one line when the period ends.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "tilth/log.h"

namespace tilth::modbus {

class LogThrottle {
 public:
  using Clock = std::chrono::steady_clock;

  LogThrottle(Logger log, LogLevel level, std::chrono::milliseconds period);

  // Logs `message` now, or counts it when a line was logged less than a period ago.
  void event(Clock::time_point now, std::string message);
  // Logs the summary of the events held back once their period is over.
  void flush(Clock::time_point now);
  // Logs the summary of the events held back now, period over or not (when stopping).
  void summarize(Clock::time_point now);
  // When flush() has a summary to log; nothing when no event is held back.
  std::optional<Clock::time_point> deadline() const;

 private:
  const Logger log_;
  const LogLevel level_;
  const std::chrono::milliseconds period_;
  std::optional<Clock::time_point> last_logged_;
  int held_back_ = 0;
  std::string latest_;  // the newest event held back
};

}  // namespace tilth::modbus
