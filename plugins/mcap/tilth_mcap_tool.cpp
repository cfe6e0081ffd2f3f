// tilth-mcap: `info FILE` and `repair FILE [OUTPUT]` on MCAP recordings, until the tilth
// command line offers them as `tilth recording info|repair`.
#include <exception>
#include <iostream>
#include <string>

#include "mcap_recording.h"

namespace {

int usage() {
  std::cerr << "usage: tilth-mcap info FILE\n"
               "       tilth-mcap repair FILE [OUTPUT]   (OUTPUT defaults to FILE)\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::string command = argv[1];
  try {
    if (command == "info" && argc == 3) {
      std::cout << tilth::mcap::format_info(tilth::mcap::recording_info(argv[2]));
      return 0;
    }
    if (command == "repair" && (argc == 3 || argc == 4)) {
      const std::string output = argc == 4 ? argv[3] : argv[2];
      const auto result = tilth::mcap::repair_recording(argv[2], output);
      std::cout << output << ": " << result.messages << " messages in " << result.chunks
                << " chunks, with a summary; " << result.lost_bytes
                << " bytes after the last complete record were dropped\n";
      return 0;
    }
  } catch (const std::exception& error) {
    std::cerr << "tilth-mcap: " << error.what() << "\n";
    return 1;
  }
  return usage();
}
