// `tilth simulate` (the tilth-simulate program): renders a preset of the scene simulator
// into an MCAP recording or an image-folder recording, by running synthetic.scene into
// the format's writer stage in process.
#include <filesystem>
#include <iostream>
#include <optional>
#include <set>
#include <string>

#include "command_line.h"
#include "commands.h"
#include "data_loss_report.h"
#include "framework/diagnostics.h"
#include "framework/install_layout.h"
#include "in_process_graph.h"
#include "output_path.h"
#include "stop_signals.h"
#include "tilth/error.h"
#include "tilth/json_input.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;

constexpr const char* kUsage = R"(usage: tilth simulate OUTPUT [OPTIONS]

Renders a scene preset of the simulator (ToF raw frames, colour frames, ground-truth
distance and residue mask) into OUTPUT: an MCAP recording when it ends in .mcap, else
an image-folder recording.

  --preset NAME          scene preset (default case_c; `tilth describe synthetic.scene`
                         lists them)
  --scene JSON           change the preset's fields, e.g. '{"straws": 600}' (the
                         fields: docs/simulator.md, "Scenes of your own")
  --frames N             frames to render (default: the preset's count)
  --seed N               scene and noise seed (default 1); the same seed gives the same
                         frames
  --fps F                render at most F frames/s, as a live camera delivers them, and
                         drop frames the writer cannot take (default 0: as fast as
                         possible, nothing dropped). Device timestamps are 30 frames/s
                         apart either way.
  --calibration FILE     rig calibration: both cameras' sizes and poses (default: the
                         paper's rig, calib/paper_rig.calib.json)
  --color-format F       bgr8 (default) or a Bayer mosaic: bayer_rggb8, bayer_bggr8, ...
  --tof-noise MM         ToF range noise (sd) at 500 mm, growing with the range squared
                         (default 1)
  --color-noise DN       colour sensor noise (sd, default 2)
  --format mcap|folder   the output format, whatever OUTPUT's extension
  --compression C        MCAP chunk compression: zstd (default), lz4 or none
  --overwrite            replace an existing OUTPUT

SIGINT or SIGTERM stops it cleanly: the frames rendered so far are written and the
recording closed (an MCAP file with its summary), exit code 0; a second signal exits at
once (code 130). Exit code 1 when it fails, 2 for bad usage, 3 when the writer could not
store every frame (a full disk; the recording holds the frames before it).
)";

int usage_error(const std::string& message) {
  std::cerr << "tilth simulate: " << message << "\n\n" << kUsage;
  return kExitUsage;
}

// Whether --fps asks for pacing; a malformed value is the stage's to report.
bool paced(const std::optional<std::string>& fps) {
  if (!fps) return false;
  try {
    const auto value = tilth::parse_json(*fps, "--fps");
    return value.is_number() && value.get<double>() > 0;
  } catch (const tilth::JsonError&) {
    return false;
  }
}

// The command as typed, for the recording's description.
std::string command_text(int argc, char** argv) {
  std::string text = "tilth simulate";
  for (int i = 1; i < argc; ++i) text += std::string(" ") + argv[i];
  return text;
}

}  // namespace

int main(int argc, char** argv) {
  tilth::tools::install_stop_handlers("tilth simulate");
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1,
                   std::set<std::string>{"--preset", "--scene", "--frames", "--seed", "--fps",
                                         "--calibration", "--color-format", "--tof-noise",
                                         "--color-noise", "--format", "--compression"},
                   std::set<std::string>{"--overwrite", "--help"});
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const CommandLine& line = *parsed;
  if (line.flag("--help")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (line.positional().size() != 1) return usage_error("expected one OUTPUT");
  const fs::path output = line.positional()[0];
  const std::string format =
      line.value("--format").value_or(output.extension() == ".mcap" ? "mcap" : "folder");
  if (format != "mcap" && format != "folder") {
    return usage_error("--format: expected mcap or folder, got '" + format + "'");
  }
  if (format == "folder" && line.value("--compression")) {
    return usage_error("--compression is for MCAP output");
  }
  const bool overwrite = line.flag("--overwrite");
  const bool live = paced(line.value("--fps"));

  try {
    tilth::tools::check_output_path(output,
                                    format == "mcap" ? tilth::tools::RecordingKind::kMcapFile
                                                     : tilth::tools::RecordingKind::kImageFolder,
                                    overwrite);
    const std::string calibration =
        (tilth::shipped_data_dir() / "calib" / "paper_rig.calib.json").string();
    tilth::tools::InProcessGraph graph("tilth simulate");
    graph.add_node("scene", "synthetic.scene", {{"calibration", calibration}});
    if (format == "mcap") {
      // Paced like a camera, the writer keeps up as a live recording does (see
      // mcap.writer's when_behind); otherwise every chunk is compressed.
      graph.add_node("writer", "mcap.writer",
                     {{"path", output.string()},
                      {"calibration", calibration},
                      {"when_behind", live ? "store" : "wait"}});
    } else {
      graph.add_node("writer", "recording.image_folder_writer",
                     {{"path", output.string()},
                      {"calibration", calibration},
                      {"overwrite", overwrite},
                      {"description", command_text(argc, argv)}});
    }
    const auto pass = [&](const std::string& option, const std::string& node,
                          const std::string& param) {
      if (const auto text = line.value(option)) graph.set_from_option(node, param, option, *text);
    };
    pass("--preset", "scene", "preset");
    pass("--scene", "scene", "scene");
    pass("--frames", "scene", "frames");
    pass("--seed", "scene", "seed");
    pass("--fps", "scene", "fps");
    pass("--color-format", "scene", "color_format");
    pass("--tof-noise", "scene", "noise_mm");
    pass("--color-noise", "scene", "color_noise");
    pass("--calibration", "scene", "calibration");
    pass("--calibration", "writer", "calibration");
    pass("--compression", "writer", "compression");
    for (const std::string port : {"raw", "color", "truth"}) {
      graph.add_edge("scene." + port, "writer." + port);
    }
    // Live, a recorder graph (docs/mcap.md, "Recording live"): a second of frames in
    // flight rides out the writer's stalls on a busy computer; beyond that the oldest
    // frame waiting is dropped.
    graph.set_runtime(
        live ? tilth::RuntimeOptions{30, tilth::FullPolicy::kDropOldest, tilth::ErrorPolicy::kStop}
             : tilth::RuntimeOptions{4, tilth::FullPolicy::kBlock, tilth::ErrorPolicy::kStop});

    const tilth::RunResult result = graph.run();
    std::cerr << tilth::tools::data_loss_report("tilth simulate", result.data_lost);
    if (result.failed) throw tilth::Error(result.failure);
    std::cout << output.string() << ": " << result.metrics.frames_completed << " frames (" << format
              << ")";
    if (live) std::cout << ", " << result.metrics.frames_dropped << " dropped";
    if (result.stopped) std::cout << "; stopped by a signal";
    std::cout << "\n";
    return result.data_lost.empty() ? kExitOk : kExitDataLost;
  } catch (const tilth::GraphError& error) {
    std::cerr << error.what() << "\n";
    return kExitUsage;
  } catch (const std::exception& error) {
    std::cerr << "tilth simulate: " << error.what() << "\n";
    return kExitFailed;
  }
}
