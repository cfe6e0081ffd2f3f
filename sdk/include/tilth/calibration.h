// The rig calibration file (spec: tilth-calibration/1): the ToF camera, the colour
// camera and the transform between them, in millimetres and 0-based pixels.
#pragma once

#include <array>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core/matx.hpp>
#include <opencv2/core/types.hpp>

namespace tilth {

struct CameraIntrinsics {
  std::string model;
  int width = 0;
  int height = 0;
  double fx = 0.0;
  double fy = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  std::array<double, 5> distortion{};  // OpenCV order k1, k2, p1, p2, k3

  bool has_distortion() const;
  cv::Matx33d camera_matrix() const;
};

// What the ToF camera's 16-bit value measures.
enum class DepthMeasure {
  kRadial,  // distance from the optical centre to the surface point (paper eq. 1)
  kZ,       // distance along the optical axis (Basler blaze Coord3D_C16)
};

struct DepthCameraCalibration : CameraIntrinsics {
  DepthMeasure depth_measure = DepthMeasure::kRadial;
  double gray_to_mm = 0.0;      // the paper's mu
  double gray_offset_mm = 0.0;  // d = g * gray_to_mm + gray_offset_mm
  double z_offset_mm = 0.0;     // optical centre behind the mounting surface
};

struct RigCalibration {
  static constexpr std::string_view kFormat = "tilth-calibration/1";

  std::string origin;  // where it was read: a file's path, or a recording's attachment
  DepthCameraCalibration depth;
  CameraIntrinsics color;
  cv::Matx33d depth_to_color_r = cv::Matx33d::eye();  // P_c = R * P_d + T
  cv::Vec3d depth_to_color_t_mm;
};

// Checks every field; throws tilth::Error naming the field by its JSON pointer and what
// was expected: "rig.calib.json:/depth_camera/fx: expected a number > 0, got 0".
RigCalibration parse_calibration(const nlohmann::json& document, const std::string& origin);
RigCalibration load_calibration(const std::filesystem::path& file);
nlohmann::json to_json(const RigCalibration& calibration);
void save_calibration(const RigCalibration& calibration, const std::filesystem::path& file);

// The rig as it is when its colour camera reads out `window` of its sensor (a region of
// interest: GenICam OffsetX, OffsetY, Width, Height): the colour camera's principal point
// moved by the window's corner, its size the window's. Throws tilth::Error when the window
// is not inside the calibrated colour image.
RigCalibration with_color_window(const RigCalibration& rig, const cv::Rect& window);
// "736x512 px at (368, 256)": a window, as messages name it.
std::string window_text(const cv::Rect& window);

std::string_view to_string(DepthMeasure measure);

}  // namespace tilth
