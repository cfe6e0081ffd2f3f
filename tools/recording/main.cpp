// `tilth recording` (the tilth-recording program): look into, repair and convert
// recordings. MCAP files are read with the mcap plugin's format library; conversions run
// the recording stages in process (conversion.h).
#include <atomic>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>

#include "command_line.h"
#include "commands.h"
#include "conversion.h"
#include "data_loss_report.h"
#include "framework/diagnostics.h"
#include "framework/nearest_names.h"
#include "mcap/mcap_recording.h"
#include "output_path.h"
#include "stop_signals.h"
#include "tilth/error.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;

constexpr const char* kUsage = R"(usage: tilth recording COMMAND ARGS

  info FILE                 an MCAP recording's channels, message counts, duration,
                            size, compression, attachments and metadata; checks
                            every CRC and lists what is damaged
  repair FILE OUTPUT        salvage an MCAP recording that was cut off while written
        [--overwrite]       (power loss, kill -9) or damaged: every intact chunk and
                            a summary into OUTPUT, a new file (never FILE itself)
  export FILE DIR           an MCAP recording to an image-folder recording
        [--overwrite]       (replace the recording in DIR)
  import DIR FILE           an image-folder recording to an MCAP recording
        [--compression zstd|lz4|none] [--overwrite]

--overwrite replaces only a recording (an MCAP file, a folder with recording.json),
and no output may be, hold or lie inside its input.

SIGINT or SIGTERM stops export and import cleanly: the frames converted so far are
written and the output closed (an MCAP file with its summary), exit code 0; it stops a
repair, which then removes its partial output and leaves FILE as it was (exit code 1).
A second signal exits at once (code 130).

Exit code 0 on success, 1 when the recording cannot be read or written, 2 for bad
usage, 3 when info finds damage, repair had to leave data out (both say what), or a
conversion's writer could not store every frame (a full disk; the output holds the
frames before it).
)";

constexpr int kExitDamaged = 3;

int usage_error(const std::string& message) {
  std::cerr << "tilth recording: " << message << "\n\n" << kUsage;
  return kExitUsage;
}

int info(const CommandLine& line) {
  if (line.positional().size() != 2 || line.flag("--overwrite") || line.value("--compression")) {
    return usage_error("info takes FILE");
  }
  const fs::path file = line.positional()[1];
  if (fs::is_directory(file)) {
    throw tilth::Error(file.string() +
                       ": is a folder; info reads MCAP files (an image-folder recording's index "
                       "is its frames.csv)");
  }
  const tilth::mcap::RecordingInfo recording = tilth::mcap::recording_info(file);
  std::cout << tilth::mcap::format_info(recording);
  if (recording.problems.empty()) return kExitOk;
  std::cerr << "tilth recording: " << file.string()
            << ": damaged (listed under integrity: " << recording.problems.size()
            << "); `tilth recording repair` salvages it\n";
  return kExitDamaged;
}

int repair(const CommandLine& line) {
  const auto& args = line.positional();
  if (args.size() != 3 || line.value("--compression")) {
    return usage_error("repair takes FILE OUTPUT [--overwrite]");
  }
  const fs::path input = args[1];
  const fs::path output = args[2];
  tilth::tools::check_apart(input, output);
  tilth::tools::check_output_path(output, tilth::tools::RecordingKind::kMcapFile,
                                  line.flag("--overwrite"));
  std::atomic<bool> stopped{false};
  const auto result = [&] {
    const tilth::tools::StopSignalWatcher watcher("tilth recording",
                                                  [&stopped] { stopped = true; });
    return tilth::mcap::repair_recording(input, output, [&stopped] { return stopped.load(); });
  }();
  std::cout << output.string() << ": " << result.messages << " messages in " << result.chunks
            << " chunks, with a summary\n";
  if (result.dropped.empty()) return kExitOk;
  for (const auto& range : result.dropped) {
    std::cerr << "tilth recording: dropped " << range.size << " bytes at offset " << range.offset
              << ": " << range.reason << "\n";
  }
  std::cerr << "tilth recording: " << input.string() << ": " << result.lost_bytes
            << " bytes could not be salvaged (" << result.dropped.size()
            << " damaged or cut-off parts, listed above); " << input.string()
            << " is left as it was\n";
  return kExitDamaged;
}

int convert(const CommandLine& line) {
  const auto& args = line.positional();
  const std::string& command = args[0];
  if (args.size() != 3) {
    return usage_error(command == "export" ? "export takes FILE DIR" : "import takes DIR FILE");
  }
  tilth::tools::ConversionOptions options;
  options.overwrite = line.flag("--overwrite");
  if (command == "export" && line.value("--compression")) {
    return usage_error("--compression is an import option");
  }
  options.compression = line.value("--compression").value_or("");
  const tilth::RunResult result = command == "export"
                                      ? tilth::tools::export_to_folder(args[1], args[2], options)
                                      : tilth::tools::import_from_folder(args[1], args[2], options);
  std::cerr << tilth::tools::data_loss_report("tilth recording", result.data_lost);
  std::cout << args[2] << ": " << result.metrics.frames_completed << " frames from " << args[1]
            << (result.stopped ? "; stopped by a signal" : "") << "\n";
  return result.data_lost.empty() ? kExitOk : kExitDataLost;
}

}  // namespace

int main(int argc, char** argv) {
  tilth::tools::install_stop_handlers("tilth recording");
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
    return usage_error("unknown command '" + command + "'" +
                       tilth::did_you_mean(command, {"info", "repair", "export", "import"}));
  } catch (const tilth::GraphError& error) {
    std::cerr << error.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << "tilth recording: " << error.what() << "\n";
    return kExitFailed;
  }
}
