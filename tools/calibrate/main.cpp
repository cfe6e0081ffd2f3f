// `tilth calibrate` (the tilth-calibrate program): a rig calibration file
// (tilth-calibration/1) solved from checkerboard views of both cameras, or imported from
// Basler's blaze + ace calibration result, and checked in the field on a recording.
// docs/calibration.md is the user's guide.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "alignment_overlay.h"
#include "basler_import.h"
#include "board_views.h"
#include "calibration_check.h"
#include "check_report.h"
#include "command_line.h"
#include "commands.h"
#include "rig_facts.h"
#include "rig_solver.h"
#include "solve_report.h"
#include "tilth/error.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;
using tilth::Error;
using tilth::RigCalibration;

constexpr const char* kUsage = R"(usage: tilth calibrate COMMAND ARGS

  solve DIR... --board COLSxROWS --square-mm S --out RIG.calib.json
      Both cameras' intrinsics and the transform between them from views of a
      checkerboard. Each DIR holds views: NAME_intensity.png (the ToF intensity,
      1 channel, 8 or 16 bits) and NAME_color.png (8 bits: BGR, grey, or a Bayer
      mosaic with --color-bayer) of the same board pose. --board counts the inner
      corners (8x5 for a board of 9x6 squares); --square-mm is a square's side.
        --depth-intrinsics calibrate|camera
                        calibrate (default): the ToF intrinsics from the views too;
                        camera: the camera's own, from --base or --depth-camera
        --depth-camera F,CX,CY
                        the ToF camera's Scan3dFocalLength, Scan3dPrincipalPointU
                        and V (px); no distortion (the camera corrects its own)
        --color-bayer RG|BG|GR|GB
                        the colour images are a Bayer mosaic (RG: GenICam BayerRG8)
        --report FILE   the report (default: OUT with .calib.json replaced by
                        .report.json): RMS per camera, stereo and view, coverage,
                        the uncertainty of R and T
  import BASLER.xml --out RIG.calib.json
      Basler's blaze + ace calibration result (calibration_<blazeSN>_<colorSN>.xml)
      as a rig calibration. The file holds no image sizes: give --depth-size and
      --color-size, or --base.

  check RECORDING
      Whether a calibration still registers the colour onto the depth: on the
      frames of an image-folder recording, how far the depth edges (straw, stubble,
      the board's edges) lie from the colour edges after registration, and the
      shift that brings them together.
        --calibration RIG.calib.json
                        check this calibration on the recording's frames instead
                        of the recording's own
        --frames N      the first N frames (default 30)
        --max-offset-px P
                        the largest offset, in depth pixels, that still holds
                        (default 1.5: the residue mask's 2 px dilation covers it)
        --overlay OUT.png
                        the registered colour of the frame with the most depth
                        edges, depth edges magenta, colour edges green
        --report OUT.json
                        per frame and overall: edges used, distances, offset, verdict

What neither the views nor Basler's file say (solve and import):
  --base RIG.calib.json   a calibration of the same rig whose other fields are kept
  --gray-to-mm G          the ToF camera's Scan3dCoordinateScale (mm per gray value)
  --gray-offset-mm O      its Scan3dCoordinateOffset (default 0)
  --z-offset-mm Z         the ToF optical centre behind the mounting surface
  --depth-measure radial|z  what the ToF value measures (default radial; a blaze's
                          Coord3D_C16 is z)
  --depth-size WxH  --color-size WxH  --depth-model NAME  --color-model NAME
Without --base, --gray-to-mm and --z-offset-mm are required.

  --overwrite             replace existing output files

Nothing is written when anything fails. Exit code 0 on success (check: the
calibration holds), 1 when the input cannot be read or solved, 2 for bad usage;
check: 4 when it says recalibrate, 5 when the frames cannot tell (too few edges).
)";

constexpr int kExitRecalibrate = 4;
constexpr int kExitCannotJudge = 5;
constexpr std::uint64_t kDefaultCheckFrames = 30;

const std::set<std::string> kCheckOptions = {"--calibration", "--frames", "--max-offset-px",
                                             "--overlay"};

const std::set<std::string> kValued = {
    "--out",           "--board",       "--square-mm",      "--depth-intrinsics", "--depth-camera",
    "--color-bayer",   "--report",      "--base",           "--depth-model",      "--color-model",
    "--depth-measure", "--gray-to-mm",  "--gray-offset-mm", "--z-offset-mm",      "--depth-size",
    "--color-size",    "--calibration", "--frames",         "--max-offset-px",    "--overlay"};

int usage_error(const std::string& message) {
  std::cerr << "tilth calibrate: " << message << "\n\n" << kUsage;
  return kExitUsage;
}

// Refuses an existing output unless --overwrite, and a folder always.
void check_output(const fs::path& output, bool overwrite) {
  if (!fs::exists(output)) return;
  if (!fs::is_regular_file(output)) {
    throw Error(output.string() + ": exists and is not a file; expected a file to write");
  }
  if (!overwrite) throw Error(output.string() + ": exists; use --overwrite to replace it");
}

// Written beside the target and renamed over it, so a failed write leaves nothing half.
void write_file(const fs::path& output, const std::string& text) {
  const fs::path partial = output.string() + ".partial";
  {
    std::ofstream out(partial);
    out << text;
    if (!out) throw Error(partial.string() + ": cannot write");
  }
  fs::rename(partial, output);
}

// The calibration checked as a reader will check it, before anything is written.
std::string checked_calibration_text(const RigCalibration& rig, const fs::path& output) {
  const nlohmann::json document = tilth::to_json(rig);
  tilth::parse_calibration(document, output.string());
  return document.dump(2) + "\n";
}

cv::Size parse_board(const std::string& text) {
  const auto x = text.find('x');
  int columns = 0;
  int rows = 0;
  const char* end = text.data() + text.size();
  const bool parsed =
      x != std::string::npos &&
      std::from_chars(text.data(), text.data() + x, columns).ptr == text.data() + x &&
      std::from_chars(text.data() + x + 1, end, rows).ptr == end;
  if (!parsed || columns < 2 || rows < 2 || columns > 100 || rows > 100) {
    throw Error(
        "--board: expected COLSxROWS, the inner corners along and across (2 to 100 "
        "each), e.g. 8x5 for a board of 9x6 squares, got '" +
        text + "'");
  }
  return {columns, rows};
}

// F,CX,CY into the ToF camera's intrinsics, without distortion.
void apply_depth_camera(const std::string& text, tilth::CameraIntrinsics& camera) {
  double values[3] = {};
  const char* at = text.data();
  const char* end = text.data() + text.size();
  for (int i = 0; i < 3; ++i) {
    const auto [stop, error] = std::from_chars(at, end, values[i]);
    const char expected = i < 2 ? ',' : '\0';
    if (error != std::errc() || (expected ? stop == end || *stop != expected : stop != end)) {
      throw Error(
          "--depth-camera: expected F,CX,CY in pixels (Scan3dFocalLength, "
          "Scan3dPrincipalPointU, Scan3dPrincipalPointV), got '" +
          text + "'");
    }
    at = stop + 1;
  }
  camera.fx = camera.fy = values[0];
  camera.cx = values[1];
  camera.cy = values[2];
  camera.distortion = {};
}

// The report's coverage grids side by side: where the board has not been yet.
void print_coverage(const nlohmann::json& coverage) {
  const auto& depth = coverage.at("depth").at("cells");
  const auto& color = coverage.at("color").at("cells");
  std::cout << "board coverage (# a corner in the cell)\n  ToF       colour\n";
  for (std::size_t row = 0; row < depth.size(); ++row) {
    std::cout << "  " << depth[row].get<std::string>() << "  " << color[row].get<std::string>()
              << "\n";
  }
}

fs::path default_report(const fs::path& calibration) {
  std::string name = calibration.string();
  const std::string suffix = ".calib.json";
  if (name.ends_with(suffix)) {
    name.resize(name.size() - suffix.size());
  } else {
    name = (calibration.parent_path() / calibration.stem()).string();
  }
  return name + ".report.json";
}

// A command refuses the options of another, rather than ignore them.
std::optional<std::string> foreign_option(const CommandLine& line,
                                          const std::set<std::string>& own) {
  for (const std::string& option : kValued) {
    if (!own.count(option) && line.value(option)) return option;
  }
  return std::nullopt;
}

int solve(const CommandLine& line) {
  const auto out = line.value("--out");
  const auto board_text = line.value("--board");
  const auto square_mm = line.real("--square-mm", 1.0, 1000.0);
  if (line.positional().size() < 2) return usage_error("solve takes DIR... (folders of views)");
  if (!out || !board_text || !square_mm) {
    return usage_error("solve needs --board COLSxROWS, --square-mm S and --out RIG.calib.json");
  }
  for (const std::string& option : kCheckOptions) {
    if (line.value(option)) return usage_error(option + " is a check option");
  }
  tilth::calibrate::SolveOptions options;
  options.inner_corners = parse_board(*board_text);
  options.square_mm = *square_mm;
  const std::string mode = line.value("--depth-intrinsics").value_or("calibrate");
  if (mode != "calibrate" && mode != "camera") {
    return usage_error("--depth-intrinsics: expected calibrate or camera, got '" + mode + "'");
  }
  options.calibrate_depth = mode == "calibrate";
  RigCalibration rig = tilth::calibrate::rig_facts(line, false);
  if (const auto depth_camera = line.value("--depth-camera")) {
    if (options.calibrate_depth) {
      return usage_error(
          "--depth-camera gives the ToF intrinsics: use it with "
          "--depth-intrinsics camera");
    }
    apply_depth_camera(*depth_camera, rig.depth);
  } else if (!options.calibrate_depth && !line.value("--base")) {
    return usage_error(
        "--depth-intrinsics camera takes the ToF intrinsics from --base or "
        "--depth-camera F,CX,CY");
  }
  const fs::path calibration = *out;
  const fs::path report = line.value("--report").value_or(default_report(calibration).string());
  check_output(calibration, line.flag("--overwrite"));
  check_output(report, line.flag("--overwrite"));
  const auto mosaic = line.value("--color-bayer")
                          ? tilth::calibrate::parse_color_mosaic(*line.value("--color-bayer"))
                          : tilth::calibrate::ColorMosaic::kNone;

  std::vector<fs::path> folders(line.positional().begin() + 1, line.positional().end());
  const auto views = tilth::calibrate::find_boards(tilth::calibrate::find_views(folders),
                                                   options.inner_corners, mosaic);
  const auto result = tilth::calibrate::solve_rig(views, rig, options, std::cout);
  const std::string calibration_text = checked_calibration_text(result.rig, calibration);
  const nlohmann::json report_document =
      tilth::calibrate::solve_report(result, options, calibration.string());
  write_file(calibration, calibration_text);
  write_file(report, report_document.dump(2) + "\n");
  print_coverage(report_document.at("coverage"));
  const auto& u = result.uncertainty;
  std::cout << calibration.string() << ": " << result.used.board.size() << " of " << views.size()
            << " views; RMS " << result.depth_rms_px << " px (ToF), " << result.color_rms_px
            << " px (colour), " << result.stereo_rms_px << " px (stereo); T = ["
            << result.rig.depth_to_color_t_mm[0] << ", " << result.rig.depth_to_color_t_mm[1]
            << ", " << result.rig.depth_to_color_t_mm[2] << "] mm +- [" << u.translation_std_mm[0]
            << ", " << u.translation_std_mm[1] << ", " << u.translation_std_mm[2] << "]\n"
            << report.string() << ": the report\n";
  return kExitOk;
}

int import(const CommandLine& line) {
  const auto out = line.value("--out");
  if (line.positional().size() != 2 || !out)
    return usage_error("import takes BASLER.xml --out RIG.calib.json");
  for (const char* option : {"--board", "--square-mm", "--depth-intrinsics", "--depth-camera",
                             "--color-bayer", "--report"}) {
    if (line.value(option)) return usage_error(std::string(option) + " is a solve option");
  }
  for (const std::string& option : kCheckOptions) {
    if (line.value(option)) return usage_error(option + " is a check option");
  }
  const fs::path calibration = *out;
  check_output(calibration, line.flag("--overwrite"));
  const RigCalibration rig = tilth::calibrate::import_basler(
      line.positional()[1], tilth::calibrate::rig_facts(line, true));
  write_file(calibration, checked_calibration_text(rig, calibration));
  std::cout << calibration.string() << ": imported from " << line.positional()[1] << "\n";
  return kExitOk;
}

void print_check(const tilth::calibrate::CheckResult& result, const std::string& recording) {
  using tilth::calibrate::Verdict;
  const auto& o = result.overall;
  std::size_t judged = 0;
  for (const auto& frame : result.frames) judged += frame.summary.cannot_judge.empty();
  const auto old_flags = std::cout.flags();
  const auto old_precision = std::cout.precision(2);
  std::cout << std::fixed;
  std::cout << recording << ": " << judged << " of " << result.frames.size() << " frames judged, "
            << o.depth_edge_pixels << " depth edge pixels, " << o.color_edge_pixels
            << " colour edge pixels\n";
  if (result.verdict != Verdict::kCannotJudge) {
    std::cout << "  depth edge to nearest colour edge: median " << o.at_zero.median_px
              << " px, 90% " << o.at_zero.p90_px << " px as registered; median "
              << o.at_best.median_px << " px, 90% " << o.at_best.p90_px << " px shifted by ("
              << o.best_shift.x << ", " << o.best_shift.y << ")\n"
              << "  offset (" << o.offset_px.x << ", " << o.offset_px.y << ") px, "
              << std::hypot(o.offset_px.x, o.offset_px.y) << " px long; spread " << result.spread_px
              << " px between frames\n";
  }
  std::cout << to_string(result.verdict) << ": " << result.reason << "\n";
  if (result.verdict == Verdict::kRecalibrate) {
    std::cout << "  recalibrate the rig (docs/calibration.md, \"Checking a rig in the field\")\n";
  }
  std::cout.flags(old_flags);
  std::cout.precision(old_precision);
}

int check(const CommandLine& line) {
  namespace calibrate = tilth::calibrate;
  if (line.positional().size() != 2) return usage_error("check takes RECORDING (an image folder)");
  if (const auto option = foreign_option(
          line, {"--calibration", "--frames", "--max-offset-px", "--overlay", "--report"})) {
    return usage_error(*option + " is not a check option");
  }
  const std::string recording = line.positional()[1];
  calibrate::ReplayOptions replay;
  if (const auto file = line.value("--calibration")) replay.calibration = *file;
  double max_offset_px = calibrate::kDefaultMaxOffsetPx;
  try {
    replay.max_frames = line.count("--frames", 1, 100000).value_or(kDefaultCheckFrames);
    max_offset_px =
        line.real("--max-offset-px", 0.0, calibrate::kSearchRadiusPx).value_or(max_offset_px);
  } catch (const Error& error) {
    return usage_error(error.what());
  }
  const auto overlay = line.value("--overlay");
  const auto report = line.value("--report");
  if (overlay && fs::path(*overlay).extension() != ".png") {
    return usage_error("--overlay: expected a file name ending in .png, got '" + *overlay + "'");
  }
  if (overlay) check_output(*overlay, line.flag("--overwrite"));
  if (report) check_output(*report, line.flag("--overwrite"));

  const calibrate::CheckResult result =
      calibrate::check_calibration(recording, replay, max_offset_px);
  if (report) {
    const nlohmann::json document =
        calibrate::check_report(result, recording, replay.calibration.value_or("").string());
    write_file(*report, document.dump(2) + "\n");
  }
  if (overlay) {
    std::ostringstream caption;
    caption << std::fixed << std::setprecision(2) << "frame " << result.overlay_frame_id << ": "
            << to_string(result.verdict) << ", offset (" << result.overall.offset_px.x << ", "
            << result.overall.offset_px.y << ") px; magenta depth edges, green colour edges";
    std::vector<std::uint8_t> png;
    cv::imencode(".png",
                 calibrate::alignment_overlay(result.overlay_bgr, result.overlay_depth_edges,
                                              result.overlay_color_edges, caption.str()),
                 png);
    write_file(*overlay, std::string(png.begin(), png.end()));
  }
  print_check(result, recording);
  switch (result.verdict) {
    case calibrate::Verdict::kHolds:
      return kExitOk;
    case calibrate::Verdict::kRecalibrate:
      return kExitRecalibrate;
    case calibrate::Verdict::kCannotJudge:
      return kExitCannotJudge;
  }
  return kExitFailed;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1, kValued, std::set<std::string>{"--overwrite", "--help"});
  } catch (const Error& error) {
    return usage_error(error.what());
  }
  const CommandLine& line = *parsed;
  if (line.flag("--help")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (line.positional().empty()) {
    return usage_error("expected a command: solve, import or check");
  }
  const std::string& command = line.positional()[0];
  try {
    if (command == "solve") return solve(line);
    if (command == "import") return import(line);
    if (command == "check") return check(line);
    return usage_error("unknown command '" + command + "'");
  } catch (const std::exception& error) {
    std::cerr << "tilth calibrate: " << error.what() << "\n";
    return kExitFailed;
  }
}
