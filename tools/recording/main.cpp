// `tilth recording` (the tilth-recording program): look into, repair and convert
// recordings, and import masks from labelling tools into them. MCAP files are read with
// the mcap plugin's format library; conversions run the recording stages in process
// (conversion.h); masks are carried onto the depth grid by the registration stage
// (mask_import.h).
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "command_line.h"
#include "command_usage.h"
#include "commands.h"
#include "conversion.h"
#include "data_loss_report.h"
#include "framework/diagnostics.h"
#include "framework/nearest_names.h"
#include "mask_import.h"
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
  import-masks DIR LABELS   masks drawn in a labelling tool into the image-folder
        --residue NAMES     recording DIR (mask/NNNNNN.png, the mask column of
        --soil NAMES        frames.csv); LABELS is the tool's export (below)
        [--grid color|depth] [--overwrite]

For repair, export and import, --overwrite replaces only a recording (an MCAP file, a
folder with recording.json), and no output may be, hold or lie inside its input.

import-masks: LABELS holds CVAT's labelmap.txt and SegmentationClass/*.png (export
format "Segmentation mask 1.1"), or LabelMe's label_names.txt (or class_names.txt)
and PNGs of class indices, palette or grey, in it or in SegmentationClassPNG/
(labelme2voc; index 255 is unknown). A mask belongs to the frame whose colour
image has its file name (000012.png: color/000012.png); a mask that matches no frame
is an error. --residue and --soil list the labels (comma-separated) that are residue
(255) and soil (0); any other label is unknown (128), and a colour or index that no
label has is an error. --grid color (the default): masks drawn on the colour images,
carried onto the depth grid through the recording's calibration (128 where a depth
pixel has no depth or the colour camera does not see it); depth: drawn on the depth
images. --overwrite replaces the frames' existing masks; frames.csv is replaced whole
(a new file renamed over it). An MCAP recording: `export` it to a folder first.

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

// "a,b" "c" -> a, b, c
std::vector<std::string> label_names(const CommandLine& line, const std::string& option) {
  std::vector<std::string> names;
  for (const std::string& value : line.values(option)) {
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = value.find(',', start);
      const std::string name = value.substr(start, comma - start);
      if (name.empty()) {
        throw tilth::Error(option + " '" + value + "': expected label names separated by commas");
      }
      names.push_back(name);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
  }
  return names;
}

// "0-4, 7, 9"
std::string index_ranges(const std::vector<std::uint64_t>& indices) {
  std::string text;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t last = i;
    while (last + 1 < indices.size() && indices[last + 1] == indices[last] + 1) ++last;
    text += (text.empty() ? "" : ", ") + std::to_string(indices[i]) +
            (last > i ? "-" + std::to_string(indices[last]) : "");
    i = last + 1;
  }
  return text;
}

int import_masks(const CommandLine& line) {
  const auto& args = line.positional();
  if (args.size() != 3 || line.value("--compression")) {
    return usage_error(
        "import-masks takes DIR LABELS --residue NAMES --soil NAMES [--grid "
        "color|depth] [--overwrite]");
  }
  tilth::tools::MaskImportOptions options;
  options.recording = args[1];
  options.labels = args[2];
  try {
    options.residue = label_names(line, "--residue");
    options.soil = label_names(line, "--soil");
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  if (options.residue.empty() && options.soil.empty()) {
    return usage_error(
        "import-masks: say which labels are residue and which soil (--residue "
        "NAMES, --soil NAMES); every other label is unknown");
  }
  const std::string grid = line.value("--grid").value_or("color");
  if (grid != "color" && grid != "depth") {
    return usage_error("--grid: expected color or depth, got '" + grid + "'");
  }
  options.depth_grid = grid == "depth";
  options.overwrite = line.flag("--overwrite");
  const auto result = tilth::tools::import_masks(options);
  const double pixels = static_cast<double>(result.residue + result.soil + result.unknown);
  const auto percent = [&](std::uint64_t count) {
    return std::to_string(static_cast<int>(100.0 * static_cast<double>(count) / pixels + 0.5)) +
           " %";
  };
  std::cout << options.recording.string() << ": " << result.imported << " masks from "
            << result.masks.string() << " (" << grid << " grid): residue "
            << percent(result.residue) << ", soil " << percent(result.soil) << ", unknown "
            << percent(result.unknown) << " of their pixels\n";
  if (!result.without_mask.empty()) {
    std::cout << result.without_mask.size() << " frames got no mask (index "
              << index_ranges(result.without_mask) << "); their mask column is as it was\n";
  }
  return kExitOk;
}

bool has_mask_options(const CommandLine& line) {
  return line.value("--grid") || !line.values("--residue").empty() ||
         !line.values("--soil").empty();
}

}  // namespace

int main(int argc, char** argv) {
  tilth::tools::install_stop_handlers("tilth recording");
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1,
                   std::set<std::string>{"--compression", "--residue", "--soil", "--grid"},
                   std::set<std::string>{"--overwrite", "--help"});
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const CommandLine& line = *parsed;
  try {
    if (line.flag("--help")) {
      std::cout << tilth::cli::help_text(kUsage, line.positional());
      return kExitOk;
    }
    if (line.positional().empty()) return usage_error("expected a command");
    const std::string& command = line.positional()[0];
    if (command == "import-masks") return import_masks(line);
    if (has_mask_options(line)) {
      return usage_error("--residue, --soil and --grid are import-masks options");
    }
    if (command == "info") return info(line);
    if (command == "repair") return repair(line);
    if (command == "export" || command == "import") return convert(line);
    return usage_error(
        "unknown command '" + command + "'" +
        tilth::did_you_mean(command, {"info", "repair", "export", "import", "import-masks"}));
  } catch (const tilth::GraphError& error) {
    std::cerr << error.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << "tilth recording: " << error.what() << "\n";
    return kExitFailed;
  }
}
