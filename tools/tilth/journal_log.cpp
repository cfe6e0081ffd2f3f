#include "journal_log.h"

#include <cstdio>
#include <cstdlib>
#include <string>

#include <sys/stat.h>
#include <syslog.h>

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
    const std::string node(where);
    const std::string text(message);
    const int sent = sd_journal_send("MESSAGE=%s: %s", node.c_str(), text.c_str(), "PRIORITY=%d",
                                     priority_of(level), "TILTH_NODE=%s", node.c_str(),
                                     "SYSLOG_IDENTIFIER=tilth", nullptr);
    if (sent < 0) {
      std::fprintf(stderr, "%s: %s: %s\n", std::string(to_string(level)).c_str(), node.c_str(),
                   text.c_str());
    }
  });
}

}  // namespace tilth::cli
