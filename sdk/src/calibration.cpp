#include "tilth/calibration.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <vector>

#include <opencv2/core.hpp>

#include "tilth/error.h"
#include "tilth/json_input.h"

namespace tilth {
namespace {

using nlohmann::json;

// The physical range of a value: a calibration outside it is not of a real rig, however
// well-formed, and would give valid-looking but wrong distances.
struct Bounds {
  double low;
  double high;
  bool low_open;    // (low, high] rather than [low, high]
  std::string why;  // said in the error
};

std::string number_text(double x) {
  std::ostringstream text;
  text << x;
  return text.str();
}

// A pinhole focal length gives a field of view of 2 atan(size / 2f) across an image
// side of `size` pixels. Machine-vision and ToF lenses span about 5 to 120 degrees; 1 to
// 160 degrees leaves room for any of them, and refuses a focal length typed in mm, or in
// the pixels of another image size, or a field of view beyond what a pinhole model with
// polynomial distortion can describe.
Bounds focal_length_bounds(int size, const char* side) {
  constexpr double kDegree = 3.14159265358979323846 / 180.0;
  return {size / 2.0 / std::tan(80 * kDegree), size / 2.0 / std::tan(0.5 * kDegree), false,
          " px: a field of view across the " + std::to_string(size) + "-px " + side +
              " between 1 and 160 degrees"};
}

// The principal point is where the optical axis meets the sensor: inside the image,
// whose pixels' centres are 0 .. size - 1 (edges at -0.5 and size - 0.5).
Bounds principal_point_bounds(int size, const char* side) {
  return {-0.5, size - 0.5, false, " px: inside the " + std::to_string(size) + "-px " + side};
}

// OpenCV's radial terms k1, k2, k3 of lenses up to 120 degrees calibrate to |k| below 1,
// with k3 of a wide lens up to a few; 10 folds the image within a normalised radius of
// 0.2 (a few degrees off axis), which no lens does. Tangential terms p1, p2 come from a
// lens mounted off-centre by a fraction of a pixel: below 0.01; 0.1 would shift a corner
// pixel by a tenth of the focal length.
const Bounds kRadialDistortion{-10.0, 10.0, false, ": radial terms k1, k2, k3 of a real lens"};
const Bounds kTangentialDistortion{-0.1, 0.1, false, ": tangential terms p1, p2 of a real lens"};

// A 16-bit ToF value spans 65535 * gray_to_mm: 1.5 m for the Basler blaze (0.0229 mm),
// 65 m for a camera that counts whole millimetres. No ToF camera ranges beyond that
// twice over.
const Bounds kGrayToMm{0.0, 2.0, true, " mm per gray value: a 16-bit range of at most 131 m"};
// The zero of the ToF distance (gray_offset_mm) and the optical centre (z_offset_mm) lie
// within the camera's housing, which is under 200 mm in every direction for any ToF
// camera made for machines (Basler blaze 100 x 81 x 64 mm).
const Bounds kGrayOffsetMm{-200.0, 200.0, false, " mm: within a ToF camera's housing"};
const Bounds kZOffsetMm{-200.0, 200.0, false,
                        " mm: the optical centre within the camera's housing, behind its "
                        "mounting surface"};
// The two cameras of a rig see the same patch of soil 0.3 to 1.5 m away: a metre apart,
// their views at working distance hardly overlap.
constexpr double kMaxBaselineMm = 1000.0;

// Reads one object of the file, remembering where it is, so every error names its field.
class Reader {
 public:
  Reader(const json& object, std::string origin, std::string pointer)
      : object_(object), origin_(std::move(origin)), pointer_(std::move(pointer)) {
    if (!object_.is_object()) fail("", "an object", object_);
  }

  void only_keys(std::initializer_list<std::string_view> known) const {
    for (const auto& [key, value] : object_.items()) {
      bool found = false;
      for (auto name : known) found = found || name == key;
      if (!found) fail("/" + key, "no such field (misspelt?)", value, false);
    }
  }

  const json* find(const std::string& key) const {
    auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }

  const json& required(const std::string& key) const {
    const json* value = find(key);
    if (value == nullptr) {
      throw Error(origin_ + ":" + pointer_ + "/" + key + ": missing required field");
    }
    return *value;
  }

  double number(const std::string& key, std::optional<double> minimum_exclusive = {}) const {
    const json& value = required(key);
    if (!value.is_number()) fail("/" + key, "a number", value);
    const double x = value.get<double>();
    if (!std::isfinite(x)) fail("/" + key, "a finite number", value);
    if (minimum_exclusive && !(x > *minimum_exclusive)) {
      std::ostringstream expected;
      expected << "a number > " << *minimum_exclusive;
      fail("/" + key, expected.str(), value);
    }
    return x;
  }

  double number(const std::string& key, const Bounds& bounds) const {
    return check(key, required(key), number(key), bounds);
  }

  double number_or(const std::string& key, double fallback, const Bounds& bounds) const {
    return find(key) ? number(key, bounds) : fallback;
  }

  // `key` may be a pointer below this object ("distortion/0"); `value` is as written.
  double check(const std::string& key, const json& value, double x, const Bounds& bounds) const {
    const bool above_low = bounds.low_open ? x > bounds.low : x >= bounds.low;
    if (above_low && x <= bounds.high) return x;
    fail("/" + key,
         "a number in " + std::string(bounds.low_open ? "(" : "[") + number_text(bounds.low) +
             ", " + number_text(bounds.high) + "]" + bounds.why,
         value);
  }

  int positive_integer(const std::string& key) const {
    const json& value = required(key);
    if (!value.is_number_integer() || value.get<long long>() <= 0 ||
        value.get<long long>() > 100000) {
      fail("/" + key, "a positive integer", value);
    }
    return value.get<int>();
  }

  std::string string_or(const std::string& key, std::string fallback) const {
    const json* value = find(key);
    if (value == nullptr) return fallback;
    if (!value->is_string()) fail("/" + key, "a string", *value);
    return value->get<std::string>();
  }

  std::vector<double> numbers(const std::string& key, std::size_t count) const {
    const json& value = required(key);
    if (!value.is_array() || value.size() != count) {
      fail("/" + key, "an array of " + std::to_string(count) + " numbers", value);
    }
    std::vector<double> result;
    for (std::size_t i = 0; i < count; ++i) {
      if (!value[i].is_number()) {
        fail("/" + key + "/" + std::to_string(i), "a number", value[i]);
      }
      if (!std::isfinite(value[i].get<double>())) {
        fail("/" + key + "/" + std::to_string(i), "a finite number", value[i]);
      }
      result.push_back(value[i].get<double>());
    }
    return result;
  }

  Reader child(const std::string& key) const {
    return Reader(required(key), origin_, pointer_ + "/" + key);
  }

  [[noreturn]] void fail(const std::string& key, const std::string& expected, const json& got,
                         bool say_expected = true) const {
    std::string text = got.dump();
    if (text.size() > 60) text = text.substr(0, 57) + "...";
    throw Error(origin_ + ":" + pointer_ + key + ": " + (say_expected ? "expected " : "") +
                expected + (say_expected ? ", got " + text : ""));
  }

  const std::string& pointer() const { return pointer_; }
  const std::string& origin() const { return origin_; }

 private:
  const json& object_;
  std::string origin_;
  std::string pointer_;
};

void read_intrinsics(const Reader& camera, CameraIntrinsics& intrinsics) {
  intrinsics.model = camera.string_or("model", "");
  intrinsics.width = camera.positive_integer("width");
  intrinsics.height = camera.positive_integer("height");
  intrinsics.fx = camera.check("fx", camera.required("fx"), camera.number("fx", 0.0),
                               focal_length_bounds(intrinsics.width, "width"));
  intrinsics.fy = camera.check("fy", camera.required("fy"), camera.number("fy", 0.0),
                               focal_length_bounds(intrinsics.height, "height"));
  intrinsics.cx = camera.number("cx", principal_point_bounds(intrinsics.width, "width"));
  intrinsics.cy = camera.number("cy", principal_point_bounds(intrinsics.height, "height"));
  if (camera.find("distortion")) {
    const auto k = camera.numbers("distortion", 5);
    for (std::size_t i = 0; i < k.size(); ++i) {
      const bool tangential = i == 2 || i == 3;
      camera.check("distortion/" + std::to_string(i), camera.required("distortion")[i], k[i],
                   tangential ? kTangentialDistortion : kRadialDistortion);
    }
    std::copy(k.begin(), k.end(), intrinsics.distortion.begin());
  }
}

json intrinsics_json(const CameraIntrinsics& c) {
  return {
      {"model", c.model}, {"width", c.width}, {"height", c.height}, {"fx", c.fx},
      {"fy", c.fy},       {"cx", c.cx},       {"cy", c.cy},         {"distortion", c.distortion}};
}

}  // namespace

bool CameraIntrinsics::has_distortion() const {
  for (double k : distortion) {
    if (k != 0.0) return true;
  }
  return false;
}

cv::Matx33d CameraIntrinsics::camera_matrix() const { return {fx, 0, cx, 0, fy, cy, 0, 0, 1}; }

std::string_view to_string(DepthMeasure measure) {
  return measure == DepthMeasure::kRadial ? "radial" : "z";
}

RigCalibration parse_calibration(const json& document, const std::string& origin) {
  const Reader root(document, origin, "");
  root.only_keys({"format", "depth_camera", "color_camera", "depth_to_color"});
  const json& format = root.required("format");
  if (format != std::string(RigCalibration::kFormat)) {
    root.fail("/format", "\"" + std::string(RigCalibration::kFormat) + "\"", format);
  }
  RigCalibration rig;
  rig.origin = origin;

  const Reader depth = root.child("depth_camera");
  depth.only_keys({"model", "width", "height", "fx", "fy", "cx", "cy", "distortion",
                   "depth_measure", "gray_to_mm", "gray_offset_mm", "z_offset_mm"});
  read_intrinsics(depth, rig.depth);
  const std::string measure = depth.string_or("depth_measure", "radial");
  if (measure == "radial") {
    rig.depth.depth_measure = DepthMeasure::kRadial;
  } else if (measure == "z") {
    rig.depth.depth_measure = DepthMeasure::kZ;
  } else {
    depth.fail("/depth_measure", "\"radial\" or \"z\"", measure);
  }
  rig.depth.gray_to_mm = depth.number("gray_to_mm", kGrayToMm);
  rig.depth.gray_offset_mm = depth.number_or("gray_offset_mm", 0.0, kGrayOffsetMm);
  rig.depth.z_offset_mm = depth.number("z_offset_mm", kZOffsetMm);

  const Reader color = root.child("color_camera");
  color.only_keys({"model", "width", "height", "fx", "fy", "cx", "cy", "distortion"});
  read_intrinsics(color, rig.color);

  const Reader extrinsics = root.child("depth_to_color");
  extrinsics.only_keys({"R", "T_mm"});
  const json& rows = extrinsics.required("R");
  if (!rows.is_array() || rows.size() != 3) extrinsics.fail("/R", "a 3x3 array of numbers", rows);
  for (int r = 0; r < 3; ++r) {
    if (!rows[r].is_array() || rows[r].size() != 3) {
      extrinsics.fail("/R/" + std::to_string(r), "a row of 3 numbers", rows[r]);
    }
    for (int c = 0; c < 3; ++c) {
      if (!rows[r][c].is_number()) {
        extrinsics.fail("/R/" + std::to_string(r) + "/" + std::to_string(c), "a number",
                        rows[r][c]);
      }
      rig.depth_to_color_r(r, c) = rows[r][c].get<double>();
    }
  }
  const cv::Matx33d should_be_identity = rig.depth_to_color_r.t() * rig.depth_to_color_r;
  const double orthogonality = cv::norm(should_be_identity - cv::Matx33d::eye(), cv::NORM_INF);
  const double determinant = cv::determinant(rig.depth_to_color_r);
  if (orthogonality > 1e-6 || std::abs(determinant - 1.0) > 1e-6) {
    std::ostringstream why;
    why << "a rotation matrix (R^T R = I, det R = +1); |R^T R - I| = " << orthogonality
        << ", det R = " << determinant;
    throw Error(origin + ":" + extrinsics.pointer() + "/R: expected " + why.str());
  }
  const auto t = extrinsics.numbers("T_mm", 3);
  rig.depth_to_color_t_mm = {t[0], t[1], t[2]};
  if (const double baseline = cv::norm(rig.depth_to_color_t_mm); baseline > kMaxBaselineMm) {
    throw Error(origin + ":" + extrinsics.pointer() + "/T_mm: expected a translation of at most " +
                number_text(kMaxBaselineMm) +
                " mm (the two cameras of one rig, seeing the same soil), got " +
                number_text(baseline) + " mm");
  }
  return rig;
}

RigCalibration load_calibration(const std::filesystem::path& file) {
  const std::string origin = file.string();
  return parse_calibration(parse_json(read_json_text(file, "calibration file"), origin), origin);
}

json to_json(const RigCalibration& rig) {
  json depth = intrinsics_json(rig.depth);
  depth["depth_measure"] = std::string(to_string(rig.depth.depth_measure));
  depth["gray_to_mm"] = rig.depth.gray_to_mm;
  depth["gray_offset_mm"] = rig.depth.gray_offset_mm;
  depth["z_offset_mm"] = rig.depth.z_offset_mm;
  json r = json::array();
  for (int row = 0; row < 3; ++row) {
    r.push_back(
        {rig.depth_to_color_r(row, 0), rig.depth_to_color_r(row, 1), rig.depth_to_color_r(row, 2)});
  }
  return {
      {"format", std::string(RigCalibration::kFormat)},
      {"depth_camera", depth},
      {"color_camera", intrinsics_json(rig.color)},
      {"depth_to_color",
       {{"R", r},
        {"T_mm",
         {rig.depth_to_color_t_mm[0], rig.depth_to_color_t_mm[1], rig.depth_to_color_t_mm[2]}}}}};
}

std::string window_text(const cv::Rect& window) {
  return std::to_string(window.width) + "x" + std::to_string(window.height) + " px at (" +
         std::to_string(window.x) + ", " + std::to_string(window.y) + ")";
}

RigCalibration with_color_window(const RigCalibration& rig, const cv::Rect& window) {
  const cv::Rect sensor(0, 0, rig.color.width, rig.color.height);
  if (window.empty() || (window & sensor) != window) {
    throw Error("colour image window " + window_text(window) +
                " is not inside the colour camera's " + std::to_string(sensor.width) + "x" +
                std::to_string(sensor.height) + " px image in the calibration " + rig.origin);
  }
  RigCalibration windowed = rig;
  windowed.origin = rig.origin + ", colour window " + window_text(window);
  windowed.color.width = window.width;
  windowed.color.height = window.height;
  windowed.color.cx = rig.color.cx - window.x;
  windowed.color.cy = rig.color.cy - window.y;
  return windowed;
}

void save_calibration(const RigCalibration& calibration, const std::filesystem::path& file) {
  std::ofstream out(file);
  if (!out) throw Error(file.string() + ": cannot write calibration file");
  out << to_json(calibration).dump(2) << "\n";
  if (!out) throw Error(file.string() + ": write failed");
}

}  // namespace tilth
