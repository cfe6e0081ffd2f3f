// Runs a fuzz target's LLVMFuzzerTestOneInput on saved inputs, without libFuzzer: the
// seed corpus and the crashers found so far (fuzz/regressions/) are replayed by plain
// ctest in every build. Each argument is an input file or a folder of them; every file
// is named on stderr before it runs, so a crash says which input it was. As under
// libFuzzer (fuzz/run.sh: -rss_limit_mb=2048), an input that makes a reader ask for more
// than 2 GiB is a bug: ASan reports the allocation; without ASan the data limit makes it
// throw std::bad_alloc, which no reader may let escape.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include <sys/resource.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace fs = std::filesystem;

namespace {

std::vector<fs::path> inputs_of(const fs::path& argument) {
  if (!fs::is_directory(argument)) return {argument};
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(argument)) {
    if (entry.is_regular_file()) files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

#if defined(__SANITIZE_ADDRESS__)
extern "C" const char* __asan_default_options() { return "max_allocation_size_mb=2048"; }
#endif

int main(int argc, char** argv) {
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  constexpr rlim_t kMaxDataBytes = rlim_t{2048} << 20;
  const rlimit data{kMaxDataBytes, kMaxDataBytes};
  if (setrlimit(RLIMIT_DATA, &data) != 0) {
    std::perror("replay: cannot limit the data size");
    return 2;
  }
#endif
  std::size_t replayed = 0;
  for (int i = 1; i < argc; ++i) {
    if (!fs::exists(argv[i])) {
      std::fprintf(stderr, "replay: %s: no such file or folder\n", argv[i]);
      return 2;
    }
    for (const fs::path& file : inputs_of(argv[i])) {
      std::vector<std::uint8_t> bytes(fs::file_size(file));
      std::ifstream in(file, std::ios::binary);
      in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
      if (!in) {
        std::fprintf(stderr, "replay: %s: cannot read\n", file.c_str());
        return 2;
      }
      std::fprintf(stderr, "replay: %s (%zu bytes)\n", file.c_str(), bytes.size());
      LLVMFuzzerTestOneInput(bytes.data(), bytes.size());
      ++replayed;
    }
  }
  if (replayed == 0) {
    std::fprintf(stderr, "replay: no input given\n");
    return 2;
  }
  std::printf("replayed %zu inputs\n", replayed);
  return 0;
}
