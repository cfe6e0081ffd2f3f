// `tilth calibrate import`: Basler's blaze + ace calibration result, written here as
// Basler's sample writes it (cv::FileStorage), into tilth-calibration/1.
#include <fstream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "temp_dir.h"
#include "test_rigs.h"

namespace tilth::testing {
namespace {

namespace fs = std::filesystem;

// Everything but `skip`; `translation` as Basler's sample stores it, 1x3.
void write_basler(const fs::path& file, const RigCalibration& rig, const std::string& skip = "",
                  const cv::Mat& translation = {}) {
  cv::FileStorage storage(file.string(), cv::FileStorage::WRITE);
  const auto put = [&](const std::string& name, const cv::Mat& value) {
    if (name != skip) storage << name << value;
  };
  put("colorCameraMatrix", cv::Mat(rig.color.camera_matrix()));
  put("colorDistortion", cv::Mat(cv::Matx<double, 1, 5>(rig.color.distortion.data())));
  put("blazeCameraMatrix", cv::Mat(rig.depth.camera_matrix()));
  put("blazeDistortion", cv::Mat(cv::Matx<double, 1, 5>(rig.depth.distortion.data())));
  put("rotation", cv::Mat(rig.depth_to_color_r));
  put("translation",
      translation.empty() ? cv::Mat(cv::Matx13d(rig.depth_to_color_t_mm.val)) : translation);
}

const std::string kFacts =
    " --depth-size 640x480 --color-size 1280x1024 --gray-to-mm 0.0229 --z-offset-mm 23.97";

TEST(BaslerImport, RoundTripsEveryNumber) {
  const TempDir dir;
  RigCalibration truth = rotated_rig();
  // Numbers that use every digit a double has.
  truth.color.fx = 1012.3456789012345;
  truth.depth.cx = 313.05123456789;
  truth.depth_to_color_t_mm = {44.123456789012, -3.5000000001, 2.4999999999};
  write_basler(dir.path() / "calibration_1_2.xml", truth);
  const auto run = run_calibrate("import " + (dir.path() / "calibration_1_2.xml").string() +
                                 " --out " + (dir.path() / "rig.calib.json").string() + kFacts +
                                 " --depth-model blaze --color-model ace");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const RigCalibration imported = load_calibration(dir.path() / "rig.calib.json");
  // Both files hold decimal text of doubles (OpenCV writes 17 significant digits, the
  // JSON writer the shortest exact form): 1e-9 is far above what text can lose and far
  // below any number a calibration means.
  constexpr double kTextRoundTrip = 1e-9;
  for (const auto& [from, to] :
       {std::pair<const CameraIntrinsics*, const CameraIntrinsics*>{&truth.depth, &imported.depth},
        {&truth.color, &imported.color}}) {
    EXPECT_NEAR(to->fx, from->fx, kTextRoundTrip);
    EXPECT_NEAR(to->fy, from->fy, kTextRoundTrip);
    EXPECT_NEAR(to->cx, from->cx, kTextRoundTrip);
    EXPECT_NEAR(to->cy, from->cy, kTextRoundTrip);
    for (int i = 0; i < 5; ++i) EXPECT_NEAR(to->distortion[i], from->distortion[i], kTextRoundTrip);
  }
  for (int i = 0; i < 9; ++i) {
    EXPECT_NEAR(imported.depth_to_color_r.val[i], truth.depth_to_color_r.val[i], kTextRoundTrip);
  }
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(imported.depth_to_color_t_mm[i], truth.depth_to_color_t_mm[i], kTextRoundTrip);
  }
  EXPECT_EQ(imported.depth.width, 640);
  EXPECT_EQ(imported.color.height, 1024);
  EXPECT_DOUBLE_EQ(imported.depth.gray_to_mm, 0.0229);
  EXPECT_DOUBLE_EQ(imported.depth.z_offset_mm, 23.97);
  EXPECT_EQ(imported.depth.model, "blaze");
  EXPECT_EQ(imported.color.model, "ace");
}

TEST(BaslerImport, KeepsWhatTheBaseSaysAndTheFileDoesNot) {
  const TempDir dir;
  RigCalibration base = straight_rig();
  base.depth.depth_measure = DepthMeasure::kZ;
  base.depth.gray_offset_mm = 1.5;
  save_calibration(base, dir.path() / "base.calib.json");
  write_basler(dir.path() / "basler.xml", rotated_rig());
  const auto run = run_calibrate("import " + (dir.path() / "basler.xml").string() + " --base " +
                                 (dir.path() / "base.calib.json").string() + " --out " +
                                 (dir.path() / "rig.calib.json").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const RigCalibration imported = load_calibration(dir.path() / "rig.calib.json");
  EXPECT_EQ(imported.depth.depth_measure, DepthMeasure::kZ);
  EXPECT_EQ(imported.depth.gray_offset_mm, 1.5);
  EXPECT_EQ(imported.color.width, 1280);
  EXPECT_EQ(imported.color.fx, rotated_rig().color.fx);  // the file's, not the base's
}

// Each bad file: exit code 1, a message naming the file and what is wrong, nothing
// written.
void expect_refused(const TempDir& dir, const std::string& file, const std::string& message) {
  const fs::path out = dir.path() / "rig.calib.json";
  const auto run =
      run_calibrate("import " + (dir.path() / file).string() + " --out " + out.string() + kFacts);
  EXPECT_EQ(run.exit_code, 1) << run.output;
  EXPECT_NE(run.output.find((dir.path() / file).string()), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(message), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
}

TEST(BaslerImport, MalformedXmlIsALocatedError) {
  const TempDir dir;
  write_basler(dir.path() / "good.xml", rotated_rig());
  std::ifstream in(dir.path() / "good.xml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  dir.write("cut.xml", text.substr(0, text.size() / 2));
  // OpenCV's parser names the file and the line where it stopped: cut.xml(N).
  expect_refused(dir, "cut.xml", "not an OpenCV FileStorage file: ");
  expect_refused(dir, "cut.xml", (dir.path() / "cut.xml").string() + "(");
}

TEST(BaslerImport, AMissingNodeIsNamed) {
  const TempDir dir;
  write_basler(dir.path() / "no_rotation.xml", rotated_rig(), "rotation");
  expect_refused(dir, "no_rotation.xml", "node 'rotation': missing; expected a 3x3 rotation");
  write_basler(dir.path() / "no_distortion.xml", rotated_rig(), "colorDistortion");
  expect_refused(dir, "no_distortion.xml", "node 'colorDistortion': missing");
}

TEST(BaslerImport, AMalformedNodeSaysWhatWasExpected) {
  const TempDir dir;
  write_basler(dir.path() / "short.xml", rotated_rig(), "", cv::Mat(cv::Matx12d(44.0, -3.5)));
  expect_refused(dir, "short.xml", "node 'translation': expected 3 numbers (mm), got 2");
  dir.write("text.xml",
            "<?xml version=\"1.0\"?>\n<opencv_storage>\n<rotation>not a matrix</rotation>\n"
            "</opencv_storage>\n");
  expect_refused(dir, "text.xml", "node 'blazeCameraMatrix': missing");
}

TEST(BaslerImport, AnExistingOutputIsReplacedOnlyWithOverwrite) {
  const TempDir dir;
  write_basler(dir.path() / "basler.xml", rotated_rig());
  const fs::path out = dir.write("rig.calib.json", "keep me");
  const std::string args =
      "import " + (dir.path() / "basler.xml").string() + " --out " + out.string() + kFacts;
  const auto refused = run_calibrate(args);
  EXPECT_EQ(refused.exit_code, 1);
  EXPECT_NE(refused.output.find("exists; use --overwrite"), std::string::npos) << refused.output;
  std::ifstream kept(out);
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), "keep me");
  EXPECT_EQ(run_calibrate(args + " --overwrite").exit_code, 0);
  EXPECT_EQ(load_calibration(out).color.fx, rotated_rig().color.fx);
}

TEST(BaslerImport, WithoutBaseTheDepthScaleIsRequired) {
  const TempDir dir;
  write_basler(dir.path() / "basler.xml", rotated_rig());
  const auto run = run_calibrate("import " + (dir.path() / "basler.xml").string() + " --out " +
                                 (dir.path() / "rig.calib.json").string() +
                                 " --depth-size 640x480 --color-size 1280x1024 --z-offset-mm 20");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("missing --gray-to-mm"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(dir.path() / "rig.calib.json"));
}

}  // namespace
}  // namespace tilth::testing
