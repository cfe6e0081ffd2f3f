// The rig calibration file: the shipped paper rig, a lossless round trip, and the exact
// error for each way a file can be wrong.
#include "tilth/calibration.h"

#include <fstream>

#include <gtest/gtest.h>

#include "tilth/error.h"

namespace tilth {
namespace {

using nlohmann::json;

const std::filesystem::path kPaperRig =
    std::filesystem::path(TILTH_SOURCE_DIR) / "calib" / "paper_rig.calib.json";

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

}  // namespace
}  // namespace tilth
