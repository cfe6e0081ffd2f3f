#include "basler_import.h"

#include <string>

#include <opencv2/core.hpp>

#include "tilth/error.h"

namespace tilth::calibrate {
namespace {

// OpenCV's parse errors put the file, the line and the reason in cv::Exception::func and
// the parser's function in err (4.6; other versions swap them): both, whichever is where.
std::string opencv_message(const cv::Exception& error) {
  return error.func.empty() ? error.err : error.err + ": " + error.func;
}

class BaslerFile {
 public:
  explicit BaslerFile(const std::filesystem::path& file) : name_(file.string()) {
    try {
      if (!storage_.open(name_, cv::FileStorage::READ)) {
        throw Error(name_ + ": cannot open Basler calibration file");
      }
    } catch (const cv::Exception& error) {
      throw Error(name_ + ": not an OpenCV FileStorage file: " + opencv_message(error));
    }
  }

  // The node as a rows x cols matrix of doubles; `cols` 0 is a vector of either shape.
  cv::Mat matrix(const std::string& node_name, int rows, int cols, const std::string& what) const {
    const cv::FileNode node = storage_[node_name];
    if (node.empty()) fail(node_name, "missing; expected " + what);
    cv::Mat value;
    try {
      node >> value;
    } catch (const cv::Exception& error) {
      fail(node_name, "expected " + what +
                          " (an opencv-matrix), got something else: " + opencv_message(error));
    }
    if (value.empty() || value.channels() != 1) {
      fail(node_name, "expected " + what + " (an opencv-matrix)");
    }
    const bool vector = cols == 0 && (value.rows == 1 || value.cols == 1);
    if (!vector && (cols == 0 || value.rows != rows || value.cols != cols)) {
      fail(node_name, "expected " + what + ", got " + std::to_string(value.rows) + "x" +
                          std::to_string(value.cols));
    }
    cv::Mat doubles;
    value.convertTo(doubles, CV_64F);
    if (vector) doubles = doubles.reshape(1, 1);
    if (!cv::checkRange(doubles)) fail(node_name, "expected finite numbers");
    return doubles;
  }

  [[noreturn]] void fail(const std::string& node_name, const std::string& message) const {
    throw Error(name_ + ": node '" + node_name + "': " + message);
  }

 private:
  std::string name_;
  cv::FileStorage storage_;
};

void read_camera(const BaslerFile& file, const std::string& prefix, CameraIntrinsics& camera) {
  const std::string matrix_node = prefix + "CameraMatrix";
  const cv::Mat k = file.matrix(matrix_node, 3, 3, "a 3x3 camera matrix");
  if (k.at<double>(0, 1) != 0.0 || k.at<double>(1, 0) != 0.0 || k.at<double>(2, 0) != 0.0 ||
      k.at<double>(2, 1) != 0.0 || k.at<double>(2, 2) != 1.0) {
    file.fail(matrix_node, "expected [fx 0 cx; 0 fy cy; 0 0 1] (no skew)");
  }
  camera.fx = k.at<double>(0, 0);
  camera.fy = k.at<double>(1, 1);
  camera.cx = k.at<double>(0, 2);
  camera.cy = k.at<double>(1, 2);

  const std::string distortion_node = prefix + "Distortion";
  const cv::Mat d = file.matrix(distortion_node, 1, 0, "OpenCV's distortion k1, k2, p1, p2[, k3]");
  // The format holds k1, k2, p1, p2, k3: a longer (rational or thin-prism) model is
  // accepted only when its further coefficients are zero.
  if (d.cols < 4) file.fail(distortion_node, "expected at least 4 coefficients (k1, k2, p1, p2)");
  for (int i = 5; i < d.cols; ++i) {
    if (d.at<double>(0, i) != 0.0) {
      file.fail(distortion_node, "coefficient " + std::to_string(i + 1) +
                                     " is not zero; expected OpenCV's 5-coefficient model");
    }
  }
  camera.distortion = {};
  for (int i = 0; i < std::min(d.cols, 5); ++i) camera.distortion[i] = d.at<double>(0, i);
}

}  // namespace

RigCalibration import_basler(const std::filesystem::path& file, RigCalibration rig) {
  const BaslerFile basler(file);
  read_camera(basler, "blaze", rig.depth);
  read_camera(basler, "color", rig.color);
  // Direction: Basler's blaze calibration sample (pylon Supplementary Package for blaze,
  // "Calibration") calls cv::stereoCalibrate(objectPoints, blazePoints, colorPoints,
  // blazeCameraMatrix, ..., colorCameraMatrix, ...) and stores its R and T as `rotation`
  // and `translation`, board squares in mm. OpenCV's calib3d.hpp on stereoCalibrate: R and
  // T "bring points given in the first camera's coordinate system to points in the second
  // camera's", so P_color = R * P_blaze + T: the format's depth_to_color as it is.
  const cv::Mat r = basler.matrix("rotation", 3, 3, "a 3x3 rotation matrix (blaze to colour)");
  const cv::Mat t = basler.matrix("translation", 1, 0, "a translation of 3 numbers in mm");
  if (t.cols != 3)
    basler.fail("translation", "expected 3 numbers (mm), got " + std::to_string(t.cols));
  rig.depth_to_color_r = cv::Matx33d(r.ptr<double>());
  rig.depth_to_color_t_mm = cv::Vec3d(t.ptr<double>());
  return rig;
}

}  // namespace tilth::calibrate
