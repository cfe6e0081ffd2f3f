#include "child_process.h"

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <iostream>

#include "tilth/error.h"

extern char** environ;

namespace tilth::train_segmenter {
namespace {

// A pipe's two ends, closed when it goes out of scope.
struct Pipe {
  int read = -1, write = -1;
  Pipe() {
    int ends[2];
    if (::pipe(ends) != 0) throw Error(std::string("cannot make a pipe: ") + std::strerror(errno));
    read = ends[0];
    write = ends[1];
  }
  ~Pipe() {
    if (read >= 0) ::close(read);
    if (write >= 0) ::close(write);
  }
  Pipe(const Pipe&) = delete;
  Pipe& operator=(const Pipe&) = delete;
};

}  // namespace

ChildResult run_child(const std::vector<std::string>& argv, const std::string& prefix) {
  Pipe output;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, output.write, STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, output.write, STDERR_FILENO);
  posix_spawn_file_actions_addclose(&actions, output.read);
  std::vector<char*> arguments;
  for (const std::string& argument : argv) arguments.push_back(const_cast<char*>(argument.c_str()));
  arguments.push_back(nullptr);
  pid_t pid = 0;
  const int started =
      ::posix_spawn(&pid, argv.front().c_str(), &actions, nullptr, arguments.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (started != 0) {
    throw Error("cannot start " + argv.front() + ": " + std::strerror(started));
  }
  ::close(output.write);
  output.write = -1;

  ChildResult result;
  std::deque<std::string> kept;
  std::size_t relayed = 0;
  std::string line;
  auto finish_line = [&] {
    if (relayed < kRelayedBytes) {
      std::cout << prefix << line << "\n" << std::flush;
      relayed += line.size() + 1;
      if (relayed >= kRelayedBytes) std::cout << prefix << "(the rest of its output not shown)\n";
    }
    kept.push_back(line.size() > 1000 ? line.substr(0, 1000) + "..." : line);
    if (kept.size() > static_cast<std::size_t>(kKeptLines)) kept.pop_front();
    line.clear();
  };
  char buffer[4096];
  for (;;) {
    const ssize_t got = ::read(output.read, buffer, sizeof buffer);
    if (got < 0 && errno == EINTR) continue;
    if (got <= 0) break;
    for (ssize_t i = 0; i < got; ++i) {
      if (buffer[i] == '\n') {
        finish_line();
      } else if (line.size() < 100'000) {
        line += buffer[i];
      }
    }
  }
  if (!line.empty()) finish_line();
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  for (const std::string& kept_line : kept) result.last_lines += kept_line + "\n";
  return result;
}

}  // namespace tilth::train_segmenter
