// `tilth recording` (the tilth-recording program): look into, repair and convert
// recordings. MCAP files are read with the mcap plugin's format library; conversions run
// the recording stages in process (conversion.h).
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>

#include "command_line.h"
#include "commands.h"
#include "conversion.h"
#include "framework/diagnostics.h"
#include "mcap_recording.h"
#include "tilth/error.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;

constexpr const char* kUsage = R"(usage: tilth recording COMMAND ARGS

  info FILE                 an MCAP recording's channels, message counts, duration,
                            size, compression, attachments and metadata
  repair FILE [OUTPUT]      rewrite an MCAP recording that was cut off while written
                            (power loss, kill -9) with every complete chunk and a
                            summary; OUTPUT defaults to FILE (replaced once complete)
  export FILE DIR           an MCAP recording to an image-folder recording
        [--overwrite]       (replace the recording in DIR)
  import DIR FILE           an image-folder recording to an MCAP recording
        [--compression zstd|lz4|none] [--overwrite]

Exit code 0 on success, 1 when the recording cannot be read or written, 2 for bad usage.
)";

int usage_error(const std::string& message) {
  std::cerr << "tilth recording: " << message << "\n\n" << kUsage;
  return kExitUsage;
}

// info and repair take no options.
bool has_options(const CommandLine& line) {
  return line.flag("--overwrite") || line.value("--compression").has_value();
}

int info(const CommandLine& line) {
  if (line.positional().size() != 2 || has_options(line)) return usage_error("info takes FILE");
  const fs::path file = line.positional()[1];
  if (fs::is_directory(file)) {
    throw tilth::Error(file.string() +
                       ": is a folder; info reads MCAP files (an image-folder recording's index "
                       "is its frames.csv)");
  }
  std::cout << tilth::mcap::format_info(tilth::mcap::recording_info(file));
  return kExitOk;
}

int repair(const CommandLine& line) {
  const auto& args = line.positional();
  if ((args.size() != 2 && args.size() != 3) || has_options(line)) {
    return usage_error("repair takes FILE [OUTPUT]");
  }
  const fs::path output = args.size() == 3 ? args[2] : args[1];
  const auto result = tilth::mcap::repair_recording(args[1], output);
  std::cout << output.string() << ": " << result.messages << " messages in " << result.chunks
            << " chunks, with a summary; " << result.lost_bytes
            << " bytes after the last complete record were dropped\n";
  return kExitOk;
}

int convert(const CommandLine& line) {
  const auto& args = line.positional();
  const std::string& command = args[0];
  if (args.size() != 3) {
    return usage_error(command == "export" ? "export takes FILE DIR" : "import takes DIR FILE");
  }
  tilth::tools::ConversionOptions options;
  options.overwrite = line.flag("--overwrite");
  if (command == "export") {
    if (line.value("--compression")) return usage_error("--compression is an import option");
    const auto frames = tilth::tools::export_to_folder(args[1], args[2], options);
    std::cout << args[2] << ": " << frames << " frames from " << args[1] << "\n";
  } else {
    options.compression = line.value("--compression").value_or("");
    const auto frames = tilth::tools::import_from_folder(args[1], args[2], options);
    std::cout << args[2] << ": " << frames << " frames from " << args[1] << "\n";
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1, std::set<std::string>{"--compression"},
                   std::set<std::string>{"--overwrite", "--help"});
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const CommandLine& line = *parsed;
  try {
    if (line.flag("--help")) {
      std::cout << kUsage;
      return kExitOk;
    }
    if (line.positional().empty()) return usage_error("expected a command");
    const std::string& command = line.positional()[0];
    if (command == "info") return info(line);
    if (command == "repair") return repair(line);
    if (command == "export" || command == "import") return convert(line);
    return usage_error("unknown command '" + command + "'");
  } catch (const tilth::GraphError& error) {
    std::cerr << error.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << "tilth recording: " << error.what() << "\n";
    return kExitFailed;
  }
}
