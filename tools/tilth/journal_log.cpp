#include "journal_log.h"

#include <cstdio>
#include <cstdlib>
#include <iterator>
#include <string>

#include <sys/stat.h>
#include <sys/uio.h>
#include <syslog.h>

// Without CODE_FILE= and friends: they would name this file, not where a line came from,
// and __FILE__ may be an absolute build path.
#define SD_JOURNAL_SUPPRESS_LOCATION
#include <systemd/sd-journal.h>

#include "tilth/log.h"

namespace tilth::cli {
namespace {

int priority_of(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug:
      return LOG_DEBUG;
    case LogLevel::kInfo:
      return LOG_INFO;
    case LogLevel::kWarning:
      return LOG_WARNING;
    case LogLevel::kError:
      return LOG_ERR;
  }
  return LOG_INFO;
}

}  // namespace

bool stderr_is_journal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  if (stream == nullptr) return false;
  unsigned long long device = 0;
  unsigned long long inode = 0;
  if (std::sscanf(stream, "%llu:%llu", &device, &inode) != 2) return false;
  struct stat status {};
  if (fstat(2, &status) != 0) return false;
  return status.st_dev == device && status.st_ino == inode;
}

void log_to_journal() {
  set_log_handler([](LogLevel level, std::string_view where, std::string_view message) {
    const std::string fields[] = {
        "MESSAGE=" + std::string(where) + ": " + std::string(message),
        "PRIORITY=" + std::to_string(priority_of(level)),
        "TILTH_NODE=" + std::string(where),
        "SYSLOG_IDENTIFIER=tilth",
    };
    iovec entry[std::size(fields)];
    for (std::size_t i = 0; i < std::size(fields); ++i) {
      entry[i] = {const_cast<char*>(fields[i].data()), fields[i].size()};
    }
    if (sd_journal_sendv(entry, static_cast<int>(std::size(fields))) < 0) {
      std::fprintf(stderr, "%s: %.*s: %.*s\n", std::string(to_string(level)).c_str(),
                   static_cast<int>(where.size()), where.data(), static_cast<int>(message.size()),
                   message.data());
    }
  });
}

}  // namespace tilth::cli
