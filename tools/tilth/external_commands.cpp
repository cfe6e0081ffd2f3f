#include "external_commands.h"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>

#include "tilth/error.h"

namespace tilth::cli {
namespace {

namespace fs = std::filesystem;
constexpr std::string_view kPrefix = "tilth-";

// The directory of this executable first, then PATH's directories in order.
std::vector<fs::path> search_directories() {
  std::vector<fs::path> directories;
  std::error_code error;
  const fs::path self = fs::read_symlink("/proc/self/exe", error);
  if (!error) directories.push_back(self.parent_path());
  if (const char* path = std::getenv("PATH")) {
    std::istringstream entries(path);
    for (std::string entry; std::getline(entries, entry, ':');) {
      if (!entry.empty()) directories.emplace_back(entry);
    }
  }
  return directories;
}

bool is_executable(const fs::path& file) {
  std::error_code error;
  return fs::is_regular_file(file, error) && ::access(file.c_str(), X_OK) == 0;
}

}  // namespace

void exec_external_command(const std::string& name, int argc, char** argv) {
  if (name.empty() || name.find('/') != std::string::npos) return;
  for (const auto& directory : search_directories()) {
    const fs::path program = directory / (std::string(kPrefix) + name);
    if (!is_executable(program)) continue;
    std::vector<char*> arguments{const_cast<char*>(program.c_str())};
    for (int i = 2; i < argc; ++i) arguments.push_back(argv[i]);
    arguments.push_back(nullptr);
    ::execv(program.c_str(), arguments.data());
    throw Error("cannot run " + program.string() + ": " + std::strerror(errno));
  }
}

std::vector<std::string> external_commands() {
  std::set<std::string> names;
  for (const auto& directory : search_directories()) {
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(directory, error)) {
      const std::string file = entry.path().filename().string();
      if (file.starts_with(kPrefix) && file.size() > kPrefix.size() &&
          is_executable(entry.path())) {
        names.insert(file.substr(kPrefix.size()));
      }
    }
  }
  return {names.begin(), names.end()};
}

}  // namespace tilth::cli
