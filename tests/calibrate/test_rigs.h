// The rigs the calibration tests render and solve, the tool they run, and the views
// they write: what tests/calibrate's files share.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include "calibration_poses.h"
#include "checkerboard_renderer.h"
#include "tilth/calibration.h"

namespace tilth::testing {

// The paper's rig: the blaze-101 (it corrects its own distortion) 45 mm beside an
// acA1300 with a distortion-free lens, axes parallel.
inline RigCalibration straight_rig() {
  RigCalibration rig;
  rig.depth.model = "Basler blaze-101";
  rig.depth.width = 640;
  rig.depth.height = 480;
  rig.depth.fx = rig.depth.fy = 509.935;
  rig.depth.cx = 313.05;
  rig.depth.cy = 239.60;
  rig.depth.gray_to_mm = 0.0229;
  rig.depth.z_offset_mm = 23.97;
  rig.color.model = "Basler acA1300-75gc";
  rig.color.width = 1280;
  rig.color.height = 1024;
  rig.color.fx = rig.color.fy = 1000.0;
  rig.color.cx = 639.5;
  rig.color.cy = 511.5;
  rig.depth_to_color_t_mm = {45.0, 0.0, 0.0};
  return rig;
}

// A rig as mounted in the field: the colour camera turned by a few degrees about each
// axis (0.6, -2.5, 3.2), shifted off the baseline, its lens distorting (barrel, a little
// decentred) with unequal focal lengths.
inline RigCalibration rotated_rig() {
  RigCalibration rig = straight_rig();
  rig.color.fx = 1012.0;
  rig.color.fy = 1006.0;
  rig.color.cx = 646.3;
  rig.color.cy = 503.8;
  rig.color.distortion = {-0.14, 0.09, 0.0008, -0.0005, 0.0};
  const double degree = CV_PI / 180.0;
  cv::Rodrigues(cv::Vec3d(0.6, -2.5, 3.2) * degree, rig.depth_to_color_r);
  rig.depth_to_color_t_mm = {44.0, -3.5, 2.5};
  return rig;
}

// The rotation between two rotation matrices, in degrees.
inline double angle_between_deg(const cv::Matx33d& a, const cv::Matx33d& b) {
  cv::Vec3d vector;
  cv::Rodrigues(a.t() * b, vector);
  return cv::norm(vector) * 180.0 / CV_PI;
}

// NNN_intensity.png (16-bit) and NNN_color.png (Bayer RG8) of each pose, in `folder`.
inline void write_views(const std::filesystem::path& folder, const RigCalibration& rig,
                        const Checkerboard& board, const std::vector<BoardPose>& poses,
                        std::uint64_t seed) {
  std::filesystem::create_directories(folder);
  cv::RNG rng(seed);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%03zu", i);
    cv::imwrite((folder / (std::string(name) + "_intensity.png")).string(),
                render_tof_intensity(rig, board, poses[i], rng));
    cv::imwrite((folder / (std::string(name) + "_color.png")).string(),
                render_color_bayer_rg(rig, board, poses[i], rng));
  }
}

struct ToolRun {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

// PROGRAM ARGS through the shell.
inline ToolRun run_program(const std::string& program, const std::string& args) {
  ToolRun run;
  FILE* pipe = popen((program + " " + args + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) run.output += buffer.data();
  const int status = pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// tilth-calibrate ARGS, the program the build made (TILTH_CALIBRATE: its path).
inline ToolRun run_calibrate(const std::string& args) { return run_program(TILTH_CALIBRATE, args); }

}  // namespace tilth::testing
