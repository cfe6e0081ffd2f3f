// `tilth calibrate solve` refusing input it cannot solve: each a clear error (exit code
// 1, what is wrong and what was expected), and nothing written.
#include <fstream>

#include <gtest/gtest.h>

#include "temp_dir.h"
#include "test_rigs.h"

namespace tilth::testing {
namespace {

namespace fs = std::filesystem;

class SolveBadInput : public ::testing::Test {
 protected:
  // `count` good views of the straight rig in views/.
  void write_good_views(int count) {
    const RigCalibration rig = straight_rig();
    write_views(views(), rig, Checkerboard{}, calibration_poses(rig, Checkerboard{}, count, 3), 4);
  }

  fs::path views() const { return dir_.path() / "views"; }
  fs::path out() const { return dir_.path() / "rig.calib.json"; }

  // Refused with exit code 1 and `message`, neither output file there.
  void expect_refused(const std::string& options, const std::string& message) {
    const auto run =
        run_calibrate("solve " + views().string() + " --out " + out().string() +
                      " --gray-to-mm 0.0229 --z-offset-mm 23.97 --color-bayer RG " + options);
    EXPECT_EQ(run.exit_code, 1) << run.output;
    EXPECT_NE(run.output.find(message), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(out()));
    EXPECT_FALSE(fs::exists(dir_.path() / "rig.report.json"));
  }

  TempDir dir_;
};

TEST_F(SolveBadInput, NoBoardInAnyView) {
  fs::create_directories(views());
  cv::RNG rng(1);
  for (const char* name : {"000", "001", "002"}) {
    cv::Mat intensity(480, 640, CV_16U);
    rng.fill(intensity, cv::RNG::UNIFORM, 200, 3000);
    cv::Mat color(1024, 1280, CV_8U);
    rng.fill(color, cv::RNG::UNIFORM, 0, 255);
    cv::imwrite((views() / (std::string(name) + "_intensity.png")).string(), intensity);
    cv::imwrite((views() / (std::string(name) + "_color.png")).string(), color);
  }
  expect_refused("--board 8x5 --square-mm 40",
                 "no view shows a board of 8x5 inner corners in both images (of 3 views, found "
                 "in 0 intensity and 0 colour images)");
}

TEST_F(SolveBadInput, TooFewViews) {
  write_good_views(4);
  expect_refused("--board 8x5 --square-mm 40",
                 "only 4 of 4 views usable (the others are listed above with why); expected at "
                 "least 6");
}

TEST_F(SolveBadInput, WrongBoardSize) {
  write_good_views(6);
  // Squares counted instead of inner corners: 9x6 is the board's squares.
  expect_refused("--board 9x6 --square-mm 40", "no view shows a board of 9x6 inner corners");
}

TEST_F(SolveBadInput, AnImageOfAnotherCamera) {
  write_good_views(6);
  // One view's colour image from a camera with another sensor.
  cv::imwrite((views() / "003_color.png").string(), cv::Mat(1200, 1920, CV_8U, cv::Scalar(128)));
  expect_refused("--board 8x5 --square-mm 40",
                 "views/003: the colour image is 1920x1200, " + views().string() +
                     "/000's 1280x1024; expected every view's from the same colour camera");
}

TEST_F(SolveBadInput, ImagesOfCamerasOtherThanTheBases) {
  write_good_views(6);
  RigCalibration base = straight_rig();
  base.color.width = 1920;
  base.color.height = 1200;
  base.color.cx = 959.5;
  base.color.cy = 599.5;
  save_calibration(base, dir_.path() / "base.calib.json");
  expect_refused("--board 8x5 --square-mm 40 --base " + (dir_.path() / "base.calib.json").string(),
                 "the views' images are 640x480 (intensity) and 1280x1024 (colour), " +
                     (dir_.path() / "base.calib.json").string() +
                     "'s cameras 640x480 and 1920x1200; expected images of the calibration's "
                     "cameras");
}

TEST_F(SolveBadInput, IntensityAndColourSwapped) {
  write_good_views(1);
  fs::rename(views() / "000_intensity.png", dir_.path() / "swap.png");
  fs::rename(views() / "000_color.png", views() / "000_intensity.png");
  fs::rename(dir_.path() / "swap.png", views() / "000_color.png");
  expect_refused("--board 8x5 --square-mm 40",
                 "000_color.png: expected an 8-bit colour image (1 channel: Bayer or grey; 3: "
                 "BGR)");
}

TEST_F(SolveBadInput, AViewWithoutItsPartner) {
  write_good_views(1);
  fs::remove(views() / "000_color.png");
  expect_refused("--board 8x5 --square-mm 40", "000_color.png is missing");
}

TEST_F(SolveBadInput, AnExistingOutputIsKept) {
  write_good_views(1);
  std::ofstream(out()) << "keep me";
  const auto run = run_calibrate("solve " + views().string() + " --out " + out().string() +
                                 " --gray-to-mm 0.0229 --z-offset-mm 23.97 --board 8x5 "
                                 "--square-mm 40");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.output.find("exists; use --overwrite to replace it"), std::string::npos)
      << run.output;
  std::ifstream kept(out());
  EXPECT_EQ(std::string(std::istreambuf_iterator<char>(kept), {}), "keep me");
}

}  // namespace
}  // namespace tilth::testing
