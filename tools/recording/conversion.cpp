#include "conversion.h"

#include <unistd.h>

#include <fstream>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "in_process_graph.h"
#include "mcap/mcap_reader.h"
#include "mcap/recording_layout.h"
#include "output_path.h"
#include "stop_signals.h"
#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth::tools {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A private folder under the system's temporary directory, removed with its contents,
// also when a second stop signal exits at once.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::string pattern = (fs::temp_directory_path() / "tilth-recording-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw Error("cannot create a temporary folder like " + pattern);
    }
    path_ = pattern;
    scratch_.push_back(std::make_unique<ScratchPath>(path_));
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;

  fs::path write(const std::string& name, const std::string& text) {
    const fs::path file = path_ / name;
    scratch_.push_back(std::make_unique<ScratchPath>(file));
    std::ofstream out(file, std::ios::binary);
    out << text;
    if (!out) throw Error(file.string() + ": cannot write");
    return file;
  }

 private:
  fs::path path_;
  std::vector<std::unique_ptr<ScratchPath>> scratch_;
};

RunResult run_conversion(InProcessGraph& graph, const std::string& what) {
  RunResult result = graph.run();
  if (result.failed) throw Error(what + " failed: " + result.failure);
  return result;
}

void connect_recording_ports(InProcessGraph& graph) {
  for (const std::string port : {"raw", "color", "truth"}) {
    graph.add_edge("player." + port, "writer." + port);
  }
}

// The calibration file that recording.json names, or its inline object written to
// `scratch`; the rest of recording.json is the source stage's to check.
fs::path folder_calibration(const fs::path& folder, TemporaryFolder& scratch) {
  const fs::path file = folder / "recording.json";
  const json recording =
      parse_json(read_json_text(file, "(is this an image-folder recording?)"), file.string());
  if (!recording.is_object()) {
    throw Error(file.string() + ": expected a JSON object (spec: tilth-image-folder/1)");
  }
  const auto calibration = recording.find("calibration");
  if (calibration == recording.end()) {
    throw Error(file.string() + ":/calibration: missing required field");
  }
  if (calibration->is_string()) return folder / calibration->get<std::string>();
  if (calibration->is_object()) return scratch.write("rig.calib.json", calibration->dump(2));
  throw Error(file.string() + ":/calibration: expected a file name or a calibration object, got " +
              calibration->dump());
}

}  // namespace

RunResult export_to_folder(const fs::path& mcap_file, const fs::path& folder,
                           const ConversionOptions& options) {
  check_apart(mcap_file, folder);
  check_output_path(folder, RecordingKind::kImageFolder, options.overwrite);
  TemporaryFolder scratch;
  fs::path calibration;
  {
    mcap::McapReader reader(mcap_file);
    const auto attachment = reader.find_attachment(mcap::kCalibrationAttachment);
    if (!attachment) {
      throw Error(mcap_file.string() + ": has no attachment named " +
                  std::string(mcap::kCalibrationAttachment) +
                  " (the rig calibration mcap.writer stores); an image folder needs one");
    }
    calibration = scratch.write(attachment->name, attachment->data);
  }
  InProcessGraph graph("tilth recording export");
  graph.add_node("player", "mcap.player",
                 {{"path", mcap_file.string()}, {"host_time", "recorded"}});
  graph.add_node("writer", "recording.image_folder_writer",
                 {{"path", folder.string()},
                  {"calibration", calibration.string()},
                  {"overwrite", options.overwrite},
                  {"description", "exported from " + mcap_file.filename().string()}});
  connect_recording_ports(graph);
  graph.set_runtime({4, FullPolicy::kBlock, ErrorPolicy::kStop});
  return run_conversion(graph, "exporting " + mcap_file.string());
}

RunResult import_from_folder(const fs::path& folder, const fs::path& mcap_file,
                             const ConversionOptions& options) {
  check_apart(folder, mcap_file);
  check_output_path(mcap_file, RecordingKind::kMcapFile, options.overwrite);
  TemporaryFolder scratch;
  InProcessGraph graph("tilth recording import");
  graph.add_node("player", "recording.image_folder",
                 {{"path", folder.string()}, {"on_missing", "stop"}, {"host_time", "recorded"}});
  // Without host_timestamps.csv (the recorded host times) the source stamps frames as it
  // plays them, which says nothing of their capture: log times are then the device times.
  const bool has_host_times = fs::exists(folder / "host_timestamps.csv");
  // Offline: every chunk compressed, however long it takes.
  graph.add_node("writer", "mcap.writer",
                 {{"path", mcap_file.string()},
                  {"calibration", folder_calibration(folder, scratch).string()},
                  {"when_behind", "wait"},
                  {"log_time", has_host_times ? "host" : "device"}});
  if (!options.compression.empty()) {
    graph.set_from_option("writer", "compression", "--compression", options.compression);
  }
  connect_recording_ports(graph);
  graph.set_runtime({4, FullPolicy::kBlock, ErrorPolicy::kStop});
  return run_conversion(graph, "importing " + folder.string());
}

}  // namespace tilth::tools
