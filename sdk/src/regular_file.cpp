#include "tilth/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "tilth/error.h"

namespace tilth {
namespace {

std::string file_type(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Closes the descriptor however the read ends.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }

 private:
  int fd_;
};

}  // namespace

std::string read_regular_file(const std::filesystem::path& file, std::uint64_t max_bytes,
                              std::string_view what) {
  const std::string name = file.string();
  // Non-blocking, so that opening a FIFO returns at once; the type is then checked on
  // the descriptor itself, not on a path that could be swapped in between.
  const Descriptor fd(::open(name.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (fd.get() < 0) throw Error(name + ": cannot open: " + std::strerror(errno));
  struct stat status {};
  if (::fstat(fd.get(), &status) != 0) {
    throw Error(name + ": cannot read its type: " + std::strerror(errno));
  }
  if (!S_ISREG(status.st_mode)) {
    throw Error(name + ": is " + file_type(status.st_mode) + "; expected a regular file (" +
                std::string(what) + ")");
  }
  const auto size = static_cast<std::uint64_t>(status.st_size);
  if (size > max_bytes) {
    throw Error(name + ": is " + std::to_string(size) + " bytes; expected at most " +
                std::to_string(max_bytes) + " for a " + std::string(what));
  }
  std::string bytes(size, '\0');
  std::uint64_t done = 0;
  while (done < size) {
    const ssize_t got = ::read(fd.get(), bytes.data() + done, size - done);
    if (got < 0 && errno == EINTR) continue;
    if (got < 0) throw Error(name + ": cannot read: " + std::strerror(errno));
    if (got == 0) break;  // shrank while read
    done += static_cast<std::uint64_t>(got);
  }
  bytes.resize(done);
  return bytes;
}

}  // namespace tilth
