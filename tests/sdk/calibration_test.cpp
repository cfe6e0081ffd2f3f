// The rig calibration file: the shipped paper rig, a lossless round trip, and the exact
// error for each way a file can be wrong.
#include "tilth/calibration.h"

#include <fstream>

#include <gtest/gtest.h>

#include "source_tree.h"
#include "temp_dir.h"
#include "tilth/error.h"

namespace tilth {
namespace {

using nlohmann::json;

const std::filesystem::path kPaperRig = testing::paper_rig_path();

json paper_rig_json() {
  std::ifstream in(kPaperRig);
  return json::parse(in);
}

std::string parse_error(const json& document) {
  try {
    parse_calibration(document, "rig.json");
  } catch (const Error& error) {
    return error.what();
  }
  return "parsed";
}

TEST(Calibration, ShippedPaperRigHasThePapersToFValues) {
  const RigCalibration rig = load_calibration(kPaperRig);
  EXPECT_EQ(rig.depth.width, 640);
  EXPECT_EQ(rig.depth.height, 480);
  EXPECT_DOUBLE_EQ(rig.depth.fx, 509.935);
  EXPECT_DOUBLE_EQ(rig.depth.cx, 313.05);
  EXPECT_DOUBLE_EQ(rig.depth.cy, 239.60);
  EXPECT_DOUBLE_EQ(rig.depth.gray_to_mm, 0.0229);
  EXPECT_DOUBLE_EQ(rig.depth.z_offset_mm, 23.97);
  EXPECT_EQ(rig.depth.depth_measure, DepthMeasure::kRadial);
  EXPECT_FALSE(rig.depth.has_distortion());
  EXPECT_EQ(rig.color.width, 1280);
  EXPECT_DOUBLE_EQ(rig.depth_to_color_t_mm[0], 45.0);
}

TEST(Calibration, OptionalFieldsTakeTheirDefaults) {
  json document = paper_rig_json();
  document["depth_camera"].erase("distortion");
  document["depth_camera"].erase("depth_measure");
  document["depth_camera"].erase("gray_offset_mm");
  document["depth_camera"].erase("model");
  const RigCalibration rig = parse_calibration(document, "rig.json");
  EXPECT_EQ(rig.depth.model, "");
  EXPECT_EQ(rig.depth.depth_measure, DepthMeasure::kRadial);
  EXPECT_EQ(rig.depth.gray_offset_mm, 0.0);
  EXPECT_FALSE(rig.depth.has_distortion());
}

TEST(Calibration, RoundTripIsLossless) {
  json document = paper_rig_json();
  document["depth_camera"]["depth_measure"] = "z";
  document["depth_camera"]["distortion"] = {-0.1, 0.02, 0.001, -0.002, 0.0003};
  const double c = std::cos(0.1);
  const double s = std::sin(0.1);
  document["depth_to_color"]["R"] = {{c, 0, s}, {0, 1, 0}, {-s, 0, c}};
  const RigCalibration rig = parse_calibration(document, "rig.json");
  const auto file = std::filesystem::temp_directory_path() / "tilth_round_trip.calib.json";
  save_calibration(rig, file);
  const RigCalibration again = load_calibration(file);
  std::filesystem::remove(file);
  EXPECT_EQ(to_json(again), to_json(rig));
  EXPECT_EQ(again.depth.depth_measure, DepthMeasure::kZ);
  EXPECT_DOUBLE_EQ(again.depth.distortion[4], 0.0003);
  EXPECT_DOUBLE_EQ(again.depth_to_color_r(0, 2), s);
}

// A window of the colour camera's sensor is that camera with its principal point moved
// by the window's corner: a point projects to the same sensor pixel, less the corner.
TEST(Calibration, AColourWindowMovesThePrincipalPointAndKeepsTheRest) {
  const RigCalibration rig = parse_calibration(paper_rig_json(), "rig.json");
  const RigCalibration windowed = with_color_window(rig, cv::Rect(288, 248, 704, 528));
  EXPECT_EQ(windowed.color.width, 704);
  EXPECT_EQ(windowed.color.height, 528);
  EXPECT_DOUBLE_EQ(windowed.color.cx, rig.color.cx - 288);
  EXPECT_DOUBLE_EQ(windowed.color.cy, rig.color.cy - 248);
  EXPECT_DOUBLE_EQ(windowed.color.fx, rig.color.fx);
  EXPECT_EQ(windowed.origin, "rig.json, colour window 704x528 px at (288, 248)");
  json expected = to_json(rig);
  expected["color_camera"]["width"] = 704;
  expected["color_camera"]["height"] = 528;
  expected["color_camera"]["cx"] = rig.color.cx - 288;
  expected["color_camera"]["cy"] = rig.color.cy - 248;
  EXPECT_EQ(to_json(windowed), expected);

  EXPECT_EQ(to_json(with_color_window(rig, cv::Rect(0, 0, 1280, 1024))), to_json(rig));
  for (const cv::Rect& outside : {cv::Rect(600, 0, 704, 528), cv::Rect(-1, 0, 100, 100),
                                  cv::Rect(0, 1000, 100, 25), cv::Rect(10, 10, 0, 10)}) {
    try {
      with_color_window(rig, outside);
      ADD_FAILURE() << outside.x << ", " << outside.y << " was taken as a window";
    } catch (const Error& error) {
      EXPECT_EQ(std::string(error.what()),
                "colour image window " + std::to_string(outside.width) + "x" +
                    std::to_string(outside.height) + " px at (" + std::to_string(outside.x) + ", " +
                    std::to_string(outside.y) +
                    ") is not inside the colour camera's 1280x1024 px image in the calibration "
                    "rig.json");
    }
  }
}

TEST(Calibration, ErrorsNameTheField) {
  json missing = paper_rig_json();
  missing["depth_camera"].erase("fx");
  EXPECT_EQ(parse_error(missing), "rig.json:/depth_camera/fx: missing required field");

  json zero_focal = paper_rig_json();
  zero_focal["color_camera"]["fy"] = 0;
  EXPECT_EQ(parse_error(zero_focal), "rig.json:/color_camera/fy: expected a number > 0, got 0");

  json short_distortion = paper_rig_json();
  short_distortion["depth_camera"]["distortion"] = {0, 0, 0};
  EXPECT_EQ(parse_error(short_distortion),
            "rig.json:/depth_camera/distortion: expected an array of 5 numbers, got [0,0,0]");

  json bad_matrix = paper_rig_json();
  bad_matrix["depth_to_color"]["R"] = {{1, 0, 0}, {0, 1, 0}};
  EXPECT_EQ(parse_error(bad_matrix),
            "rig.json:/depth_to_color/R: expected a 3x3 array of numbers, got [[1,0,0],[0,1,0]]");

  json scaled = paper_rig_json();
  scaled["depth_to_color"]["R"] = {{2, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_EQ(parse_error(scaled),
            "rig.json:/depth_to_color/R: expected a rotation matrix (R^T R = I, det R = +1); "
            "|R^T R - I| = 3, det R = 2");

  json mirrored = paper_rig_json();
  mirrored["depth_to_color"]["R"] = {{-1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_EQ(parse_error(mirrored),
            "rig.json:/depth_to_color/R: expected a rotation matrix (R^T R = I, det R = +1); "
            "|R^T R - I| = 0, det R = -1");

  json measure = paper_rig_json();
  measure["depth_camera"]["depth_measure"] = "depth";
  EXPECT_EQ(parse_error(measure),
            "rig.json:/depth_camera/depth_measure: expected \"radial\" or \"z\", got \"depth\"");

  json misspelt = paper_rig_json();
  misspelt["depth_camera"]["z_ofset_mm"] = 1;
  EXPECT_EQ(parse_error(misspelt), "rig.json:/depth_camera/z_ofset_mm: no such field (misspelt?)");

  json format = paper_rig_json();
  format["format"] = "tilth-calibration/2";
  EXPECT_EQ(parse_error(format),
            "rig.json:/format: expected \"tilth-calibration/1\", got \"tilth-calibration/2\"");

  json width = paper_rig_json();
  width["depth_camera"]["width"] = 640.5;
  EXPECT_EQ(parse_error(width),
            "rig.json:/depth_camera/width: expected a positive integer, got 640.5");
}

TEST(Calibration, UnreadableFile) {
  EXPECT_THROW(load_calibration("/nonexistent.calib.json"), Error);
}

std::string load_error(const std::filesystem::path& file) {
  try {
    load_calibration(file);
  } catch (const Error& error) {
    return error.what();
  }
  return "loaded";
}

// Each of these was accepted and gave valid-looking distances: z_offset_mm 600 put the
// soil 58 mm above the camera, gray_to_mm 1e6 at 2.4e10 mm.
TEST(Calibration, ValuesNoRealRigHasAreRefused) {
  const auto refused = [](const char* camera, const char* key, const json& value) {
    json document = paper_rig_json();
    document[camera][key] = value;
    return parse_error(document);
  };
  EXPECT_EQ(refused("depth_camera", "z_offset_mm", 600),
            "rig.json:/depth_camera/z_offset_mm: expected a number in [-200, 200] mm: the optical "
            "centre within the camera's housing, behind its mounting surface, got 600");
  EXPECT_EQ(refused("depth_camera", "gray_to_mm", 1e6),
            "rig.json:/depth_camera/gray_to_mm: expected a number in (0, 2] mm per gray value: a "
            "16-bit range of at most 131 m, got 1000000.0");
  EXPECT_EQ(refused("depth_camera", "gray_offset_mm", 1e6),
            "rig.json:/depth_camera/gray_offset_mm: expected a number in [-200, 200] mm: within a "
            "ToF camera's housing, got 1000000.0");
  // 1250 px is a 54 degree view across the colour camera's 1280 px; 5 px would be 179.
  EXPECT_EQ(refused("color_camera", "fx", 5),
            "rig.json:/color_camera/fx: expected a number in [112.849, 73336.7] px: a field of "
            "view across the 1280-px width between 1 and 160 degrees, got 5");
  EXPECT_EQ(refused("depth_camera", "fy", 4.8),  // the lens's focal length in mm
            "rig.json:/depth_camera/fy: expected a number in [42.3185, 27501.3] px: a field of "
            "view across the 480-px height between 1 and 160 degrees, got 4.8");
  EXPECT_EQ(refused("color_camera", "cx", 1280),
            "rig.json:/color_camera/cx: expected a number in [-0.5, 1279.5] px: inside the 1280-px "
            "width, got 1280");
  EXPECT_EQ(refused("depth_camera", "cy", -1),
            "rig.json:/depth_camera/cy: expected a number in [-0.5, 479.5] px: inside the 480-px "
            "height, got -1");
  EXPECT_EQ(refused("depth_camera", "distortion", json{0, 0, 0.5, 0, 0}),
            "rig.json:/depth_camera/distortion/2: expected a number in [-0.1, 0.1]: tangential "
            "terms p1, p2 of a real lens, got 0.5");
  EXPECT_EQ(refused("color_camera", "distortion", json{0, 0, 0, 0, -40}),
            "rig.json:/color_camera/distortion/4: expected a number in [-10, 10]: radial terms "
            "k1, k2, k3 of a real lens, got -40");
  json far = paper_rig_json();
  far["depth_to_color"]["T_mm"] = {1200, 0, 500};
  EXPECT_EQ(parse_error(far),
            "rig.json:/depth_to_color/T_mm: expected a translation of at most 1000 mm (the two "
            "cameras of one rig, seeing the same soil), got 1300 mm");
}

TEST(Calibration, BoundsAdmitRealRigs) {
  json document = paper_rig_json();
  document["depth_camera"]["gray_to_mm"] = 1.0;  // a camera counting whole millimetres
  document["depth_camera"]["gray_offset_mm"] = -150;
  document["depth_camera"]["z_offset_mm"] = 0;
  document["depth_camera"]["cx"] = -0.5;  // the image's edges
  document["depth_camera"]["cy"] = 479.5;
  document["color_camera"]["fx"] = 300;  // a 130 degree wide-angle lens
  document["color_camera"]["distortion"] = {-0.3, 0.12, 0.001, -0.001, -0.02};
  document["depth_to_color"]["T_mm"] = {0, -600, 0};
  const RigCalibration rig = parse_calibration(document, "rig.json");
  EXPECT_EQ(rig.depth.gray_to_mm, 1.0);
  EXPECT_EQ(rig.depth.cx, -0.5);
  EXPECT_EQ(rig.color.distortion[4], -0.02);
}

TEST(Calibration, FileWithADuplicateKeyIsRefused) {
  testing::TempDir dir;
  std::ifstream in(kPaperRig);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // The last "fx" was kept: 497 px where the rig has 518 gives distances 4 % off.
  text.replace(text.find("\"fx\": 509.935,"), 14, "\"fx\": 497, \"fx\": 509.935,");
  const auto file = dir.write("rig.calib.json", text);
  EXPECT_EQ(load_error(file), file.string() +
                                  ":/depth_camera/fx: expected each key once in an object, got "
                                  "\"fx\" again");
}

TEST(Calibration, FileBeyondWhatJsonReadersTakeIsRefused) {
  testing::TempDir dir;
  const auto deep = dir.write("deep.calib.json", "{\"format\": " + std::string(50'000, '[') +
                                                     std::string(50'000, ']') + "}");
  EXPECT_NE(load_error(deep).find(":/format/0/0/"), std::string::npos);
  EXPECT_NE(load_error(deep).find(": expected at most 64 nested arrays and objects, got more"),
            std::string::npos);

  std::ifstream in(kPaperRig);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("0.0229"), 6, "1e400");
  const auto overflow = dir.write("overflow.calib.json", text);
  EXPECT_EQ(load_error(overflow), overflow.string() +
                                      ":/depth_camera/gray_to_mm: expected a number within double "
                                      "range (magnitude below 1.8e308), got 1e400");

  EXPECT_EQ(load_error("/dev/zero"),
            "/dev/zero: is a character device; expected a regular file (calibration file)");
}

}  // namespace
}  // namespace tilth
