// `tilth calibrate` (the tilth-calibrate program): a rig calibration file
// (tilth-calibration/1) solved from checkerboard views of both cameras, or imported from
// Basler's blaze + ace calibration result, and checked in the field on a recording; the
// colour camera window a rig's measured region needs.
// docs/calibration.md is the user's guide.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <limits>
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
#include "color_window/region_window.h"
#include "command_line.h"
#include "command_usage.h"
#include "commands.h"
#include "framework/nearest_names.h"
#include "number_pair.h"
#include "rig_facts.h"
#include "rig_solver.h"
#include "roi/region_of_interest.h"
#include "solve_report.h"
#include "stop_signals.h"
#include "tilth/error.h"
#include "view_capture.h"

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

  capture (--recording DIR | --tof CAMERA --color CAMERA) --board COLSxROWS
          --out DIR
      Views for solve, from a stream of frame pairs: a pair is kept when the board
      is found in both images, held still, and placed unlike every view kept so
      far (its position, size and skew in the colour image, as ROS's
      camera_calibration measures them). Each kept view is written at once as
      DIR/NNN_intensity.png and DIR/NNN_color.png (BGR or grey), and the parts of
      either image the board has not reached yet are printed.
        --recording DIR an image-folder recording whose depth images hold the ToF
                        intensity (recorded with the ToF camera's Intensity component)
        --tof CAMERA --color CAMERA
                        live, from the GigE Vision cameras (an address, serial number
                        or device id): the ToF camera streams its Intensity component
                        in Mono16, paired with the colour camera by capture time
        --views N       stop after keeping N views (default 20)
        --frames N      look at N frame pairs at most
        --still-px P    how far the board's corners may move between pairs, in each
                        image's pixels, and still count as held still (default 1)
        --set NODE.PARAM=VALUE
                        a parameter of the graph's nodes, as tilth run --set: live,
                        tof and color (aravis.tof_camera, aravis.color_camera: e.g.
                        tof.exposure_us=800) and pair (pairing.depth_color); from a
                        recording, recording (recording.image_folder)

  color-window RIG.calib.json --distance-mm NEAR:FAR
      The window of the colour camera's image that registration reads for the
      measured region when the ground is NEAR to FAR mm from the mounting surface,
      as the GenICam features that make the camera read out only that (fewer bytes
      per frame: pairs complete sooner). Put them in the colour camera's
      "features"; frames then say where on the sensor they lie, and registration
      and recordings use the window's calibration (docs/cameras.md).
        --roi R         the chain's roi: middle_half (default), image, or
                        {"x": X, "y": Y, "width": W, "height": H} in depth pixels
        --step N        corner and size in multiples of N px, even (default 16;
                        the camera's Width, Height, OffsetX and OffsetY increments)

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
check: 4 when it says recalibrate, 5 when the frames cannot tell (too few edges, or
no distinct best shift);
capture: 5 when it kept fewer views than solve needs (6).
)";

constexpr int kExitRecalibrate = 4;
constexpr int kExitCannotJudge = 5;
constexpr std::uint64_t kDefaultCheckFrames = 30;
constexpr std::uint64_t kDefaultViews = 20;

// What neither the views nor Basler's file say (rig_facts.h).
const std::set<std::string> kRigFactOptions = {
    "--base",           "--depth-model", "--color-model", "--depth-measure", "--gray-to-mm",
    "--gray-offset-mm", "--z-offset-mm", "--depth-size",  "--color-size"};

std::set<std::string> with_rig_facts(std::set<std::string> options) {
  options.insert(kRigFactOptions.begin(), kRigFactOptions.end());
  return options;
}

const std::set<std::string> kSolveOptions =
    with_rig_facts({"--out", "--board", "--square-mm", "--depth-intrinsics", "--depth-camera",
                    "--color-bayer", "--report"});
const std::set<std::string> kImportOptions = with_rig_facts({"--out"});
const std::set<std::string> kCheckOptions = {"--calibration", "--frames", "--max-offset-px",
                                             "--overlay", "--report"};
const std::set<std::string> kColorWindowOptions = {"--distance-mm", "--roi", "--step"};
const std::set<std::string> kCaptureOptions = {"--recording", "--tof",      "--color",
                                               "--board",     "--out",      "--views",
                                               "--frames",    "--still-px", "--set"};

std::set<std::string> all_valued() {
  std::set<std::string> all;
  for (const auto* options :
       {&kSolveOptions, &kImportOptions, &kCheckOptions, &kCaptureOptions, &kColorWindowOptions}) {
    all.insert(options->begin(), options->end());
  }
  return all;
}

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
  const auto board = tilth::calibrate::number_pair<int>(text, 'x');
  const int columns = board ? board->first : 0;
  const int rows = board ? board->second : 0;
  if (columns < 2 || rows < 2 || columns > 100 || rows > 100) {
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
  for (const std::string& option : all_valued()) {
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
  if (const auto option = foreign_option(line, kSolveOptions)) {
    return usage_error(*option + " is not a solve option");
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
                          : std::nullopt;

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
  if (const auto option = foreign_option(line, kImportOptions)) {
    return usage_error(*option + " is not an import option");
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
  const std::size_t judged = result.judged_frames;
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
  if (const auto option = foreign_option(line, kCheckOptions)) {
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
  // Both made before either is written: nothing is written when anything fails.
  std::vector<std::uint8_t> png;
  if (overlay) {
    std::ostringstream caption;
    caption << std::fixed << std::setprecision(2) << "frame " << result.overlay_frame_id << ": "
            << to_string(result.verdict) << ", offset (" << result.overall.offset_px.x << ", "
            << result.overall.offset_px.y << ") px; magenta depth edges, green colour edges";
    if (!cv::imencode(".png",
                      calibrate::alignment_overlay(result.overlay_bgr, result.overlay_depth_edges,
                                                   result.overlay_color_edges, caption.str()),
                      png)) {
      throw Error(*overlay + ": cannot encode the overlay as PNG");
    }
  }
  if (report) {
    const nlohmann::json document =
        calibrate::check_report(result, recording, replay.calibration.value_or("").string());
    write_file(*report, document.dump(2) + "\n");
  }
  if (overlay) write_file(*overlay, std::string(png.begin(), png.end()));
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

// NODE.PARAM=VALUE
tilth::calibrate::NodeSetting node_setting(const std::string& text) {
  const auto equals = text.find('=');
  const auto dot = text.find('.');
  if (equals == std::string::npos || dot == std::string::npos || dot == 0 || dot + 1 >= equals) {
    throw Error("--set: expected NODE.PARAM=VALUE (e.g. tof.exposure_us=800), got '" + text + "'");
  }
  return {text.substr(0, dot), text.substr(dot + 1, equals - dot - 1), text.substr(equals + 1),
          "--set " + text};
}

int capture(const CommandLine& line) {
  namespace calibrate = tilth::calibrate;
  if (line.positional().size() != 1) return usage_error("capture takes no arguments, only options");
  if (const auto option = foreign_option(line, kCaptureOptions)) {
    return usage_error(*option + " is not a capture option");
  }
  const auto recording = line.value("--recording");
  const auto tof = line.value("--tof");
  const auto color = line.value("--color");
  const auto out = line.value("--out");
  const auto board = line.value("--board");
  if (!out || !board) return usage_error("capture needs --board COLSxROWS and --out DIR");
  if (recording.has_value() == (tof.has_value() || color.has_value()) ||
      tof.has_value() != color.has_value()) {
    return usage_error("capture reads --recording DIR, or --tof CAMERA and --color CAMERA");
  }
  calibrate::CaptureOptions options;
  options.out = *out;
  options.selection.inner_corners = parse_board(*board);
  calibrate::PairStream stream;
  stream.source = recording ? calibrate::PairSource(fs::path(*recording))
                            : calibrate::PairSource(calibrate::LiveCameras{*tof, *color});
  try {
    options.views = line.count("--views", 1, 1000).value_or(kDefaultViews);
    stream.max_frames = line.count("--frames", 1, std::numeric_limits<std::uint32_t>::max());
    options.selection.still_px = line.real("--still-px", 0.05, 100.0).value_or(1.0);
    for (const std::string& text : line.values("--set"))
      stream.settings.push_back(node_setting(text));
  } catch (const Error& error) {
    return usage_error(error.what());
  }
  const calibrate::CaptureResult result = calibrate::capture_views(stream, options, std::cout);
  std::cout << options.out.string() << ": " << result.kept << " views kept from " << result.pairs
            << " frame pairs (the board in both images in " << result.board_pairs << ")"
            << (result.stopped ? "; stopped" : "") << "\n";
  if (result.color_coverage) {
    std::cout << "board coverage (# a corner in the cell)\n  ToF       colour\n";
    const auto& depth = result.depth_coverage->cells();
    const auto& colour = result.color_coverage->cells();
    for (std::size_t row = 0; row < depth.size(); ++row) {
      std::cout << "  " << depth[row] << "  " << colour[row] << "\n";
    }
  }
  if (result.kept < calibrate::kMinViews) {
    std::cout << "fewer views than solve needs (" << calibrate::kMinViews
              << "); better 15 to 20 spread over both images\n";
    return kExitCannotJudge;
  }
  return kExitOk;
}

// NEAR:FAR in mm.
std::pair<double, double> parse_distances(const std::string& text) {
  const auto range = tilth::calibrate::number_pair<double>(text, ':');
  if (!range || !(range->first > 0) || !(range->second >= range->first)) {
    throw Error(
        "--distance-mm: expected NEAR:FAR in mm with 0 < NEAR <= FAR (e.g. 400:700), got '" + text +
        "'");
  }
  return *range;
}

int color_window(const CommandLine& line) {
  if (line.positional().size() != 2) {
    return usage_error("color-window takes RIG.calib.json and --distance-mm NEAR:FAR");
  }
  if (const auto option = foreign_option(line, kColorWindowOptions)) {
    return usage_error(*option + " is not a color-window option");
  }
  const auto distances = line.value("--distance-mm");
  if (!distances) return usage_error("color-window needs --distance-mm NEAR:FAR");
  std::pair<double, double> range;
  int step = 16;
  nlohmann::json roi_value = "middle_half";
  try {
    range = parse_distances(*distances);
    step = static_cast<int>(line.count("--step", 2, 1024).value_or(16));
    if (step % 2 != 0) {
      throw Error(
          "--step: expected an even number of px (a Bayer mosaic keeps the pattern "
          "its pixel format names only at even offsets), got " +
          std::to_string(step));
    }
    if (const auto roi = line.value("--roi")) {
      roi_value = nlohmann::json::accept(*roi) ? nlohmann::json::parse(*roi) : nlohmann::json(*roi);
    }
  } catch (const Error& error) {
    return usage_error(error.what());
  }
  const RigCalibration rig = tilth::load_calibration(line.positional()[1]);
  const tilth::RegionOfInterest roi(roi_value, tilth::RegionOfInterest::Whole::kImage);
  const cv::Size depth_size(rig.depth.width, rig.depth.height);
  const cv::Rect region = roi.around(depth_size, tilth::RegionOfInterest::kMarginPx);
  const cv::Rect window = tilth::color_window_for(rig, region, range.first, range.second, step);
  const double share = 100.0 * window.area() / (rig.color.width * rig.color.height);
  std::cout << "region " << roi_value.dump() << ": depth x " << region.x << ".."
            << region.x + region.width - 1 << ", y " << region.y << ".."
            << region.y + region.height - 1 << " with the " << tilth::RegionOfInterest::kMarginPx
            << " px the segmentation reads\n"
            << "colour window for ground " << range.first << " to " << range.second
            << " mm away: " << window.width << "x" << window.height << " px at (" << window.x
            << ", " << window.y << "), " << std::lround(share) << " % of the " << rig.color.width
            << "x" << rig.color.height << " px image\n"
            << "\"features\": [{\"Width\": " << window.width << "}, {\"Height\": " << window.height
            << "}, {\"OffsetX\": " << window.x << "}, {\"OffsetY\": " << window.y << "}]\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  tilth::tools::install_stop_handlers("tilth calibrate");
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1, all_valued(), std::set<std::string>{"--overwrite", "--help"});
  } catch (const Error& error) {
    return usage_error(error.what());
  }
  const CommandLine& line = *parsed;
  if (line.flag("--help")) {
    std::cout << tilth::cli::help_text(kUsage, line.positional());
    return kExitOk;
  }
  if (line.positional().empty()) {
    return usage_error("expected a command: solve, import, check, capture or color-window");
  }
  const std::string& command = line.positional()[0];
  try {
    if (command == "solve") return solve(line);
    if (command == "import") return import(line);
    if (command == "check") return check(line);
    if (command == "capture") return capture(line);
    if (command == "color-window") return color_window(line);
    return usage_error(
        "unknown command '" + command + "'" +
        tilth::did_you_mean(command, {"solve", "import", "check", "capture", "color-window"}));
  } catch (const std::exception& error) {
    std::cerr << "tilth calibrate: " << error.what() << "\n";
    return kExitFailed;
  }
}
