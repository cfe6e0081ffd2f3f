#include "tilth/log.h"

#include <cstdio>
#include <mutex>
#include <utility>

namespace tilth {
namespace {

std::mutex& log_mutex() {
  static std::mutex mutex;
  return mutex;
}
LogHandler& handler() {
  static LogHandler installed;
  return installed;
}
LogLevel& minimum_level() {
  static LogLevel level = LogLevel::kInfo;
  return level;
}

}  // namespace

std::string_view to_string(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return "debug";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kWarning:
      return "warning";
    case LogLevel::kError:
      return "error";
  }
  return "?";
}

void log(LogLevel level, std::string_view where, std::string_view message) {
  std::lock_guard lock(log_mutex());
  if (level < minimum_level()) return;
  if (handler()) {
    handler()(level, where, message);
    return;
  }
  std::fprintf(stderr, "%.*s: %.*s: %.*s\n", static_cast<int>(to_string(level).size()),
               to_string(level).data(), static_cast<int>(where.size()), where.data(),
               static_cast<int>(message.size()), message.data());
}

LogHandler set_log_handler(LogHandler replacement) {
  std::lock_guard lock(log_mutex());
  return std::exchange(handler(), std::move(replacement));
}

void set_log_level(LogLevel minimum) {
  std::lock_guard lock(log_mutex());
  minimum_level() = minimum;
}

}  // namespace tilth
