// Logging shared by the runtime and plugins: one line per event, tagged with where it
// happened (a node name, "runtime", a file).
#pragma once

#include <functional>
#include <string>
#include <string_view>

namespace tilth {

enum class LogLevel { kDebug, kInfo, kWarning, kError };

std::string_view to_string(LogLevel level);

// Thread-safe. Writes to stderr unless a handler is installed.
void log(LogLevel level, std::string_view where, std::string_view message);

using LogHandler = std::function<void(LogLevel, std::string_view where, std::string_view message)>;
// Replaces the destination of all log lines (an empty handler restores stderr); returns
// the previous handler.
LogHandler set_log_handler(LogHandler handler);
void set_log_level(LogLevel minimum);

// A logger bound to one place, as stages receive it.
class Logger {
 public:
  explicit Logger(std::string where) : where_(std::move(where)) {}
  void debug(std::string_view message) const { log(LogLevel::kDebug, where_, message); }
  void info(std::string_view message) const { log(LogLevel::kInfo, where_, message); }
  void warning(std::string_view message) const { log(LogLevel::kWarning, where_, message); }
  void error(std::string_view message) const { log(LogLevel::kError, where_, message); }
  const std::string& where() const { return where_; }

 private:
  std::string where_;
};

}  // namespace tilth
