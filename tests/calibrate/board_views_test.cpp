// The views `tilth calibrate solve` reads: every image type it accepts gives the board's
// corners where the lens model puts them, and pairs are found by name.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "board_views.h"
#include "temp_dir.h"
#include "test_rigs.h"
#include "tilth/error.h"

namespace tilth::testing {
namespace {

namespace fs = std::filesystem;

// The RMS distance of found corners from the truth, in the board's order or reversed
// (find_board starts from the end nearer the image's top left).
double rms_from_truth(std::vector<cv::Point2f> found, const std::vector<cv::Point2d>& truth) {
  if (found.size() != truth.size()) return 1e9;
  if (cv::norm(cv::Point2d(found.front()) - truth.front()) >
      cv::norm(cv::Point2d(found.back()) - truth.front())) {
    std::reverse(found.begin(), found.end());
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    sum += std::pow(cv::norm(cv::Point2d(found[i]) - truth[i]), 2);
  }
  return std::sqrt(sum / truth.size());
}

class BoardViews : public ::testing::Test {
 protected:
  void SetUp() override {
    pose_ = calibration_poses(rig_, board_, 1, 2).front();
    cv::RNG rng(8);
    intensity_ = render_tof_intensity(rig_, board_, pose_, rng);
    mosaic_ = render_color_bayer_rg(rig_, board_, pose_, rng);
  }

  // find_board on `intensity` and `color` written as view NAME.
  calibrate::BoardView found(const cv::Mat& intensity, const cv::Mat& color,
                             std::optional<PixelFormat> mosaic) {
    cv::imwrite((dir_.path() / "v_intensity.png").string(), intensity);
    cv::imwrite((dir_.path() / "v_color.png").string(), color);
    const auto views = calibrate::find_views({dir_.path()});
    EXPECT_EQ(views.size(), 1u);
    return calibrate::find_board(views.front(), board_.inner_corners, mosaic);
  }

  // Corner accuracy on rendered images: about 0.1 px (checkerboard_renderer_test); 0.3
  // px would mean a wrongly read image (a channel order, a Bayer pattern, a scale).
  void expect_corners(const calibrate::BoardView& view) {
    EXPECT_LT(rms_from_truth(view.depth_corners, projected_corners(rig_, board_, pose_, false)),
              0.3);
    EXPECT_LT(rms_from_truth(view.color_corners, projected_corners(rig_, board_, pose_, true)),
              0.3);
  }

  const RigCalibration rig_ = rotated_rig();
  const Checkerboard board_;
  BoardPose pose_;
  cv::Mat intensity_;
  cv::Mat mosaic_;
  TempDir dir_;
};

TEST_F(BoardViews, SixteenBitIntensityAndBayerMosaic) {
  expect_corners(found(intensity_, mosaic_, PixelFormat::kBayerRggb8));
}

TEST_F(BoardViews, EightBitIntensityAndBgrColour) {
  cv::Mat intensity8;
  intensity_.convertTo(intensity8, CV_8U, 255.0 / 3500.0);
  cv::Mat bgr;
  cv::cvtColor(mosaic_, bgr, cv::COLOR_BayerBG2BGR);
  expect_corners(found(intensity8, bgr, std::nullopt));
}

TEST_F(BoardViews, GreyColour) {
  cv::Mat grey;
  cv::cvtColor(mosaic_, grey, cv::COLOR_BayerBG2GRAY);
  expect_corners(found(intensity_, grey, std::nullopt));
}

TEST_F(BoardViews, BgrColourCalledBayerIsRefused) {
  cv::Mat bgr;
  cv::cvtColor(mosaic_, bgr, cv::COLOR_BayerBG2BGR);
  try {
    found(intensity_, bgr, PixelFormat::kBayerRggb8);
    ADD_FAILURE() << "a 3-channel image read as a Bayer mosaic";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("v_color.png: has 3 channels, but --color-bayer"),
              std::string::npos)
        << error.what();
  }
}

TEST_F(BoardViews, PairsAreFoundByNameInEachFolderInOrder) {
  for (const char* name : {"b/010", "a/002", "a/001"}) {
    dir_.write(std::string(name) + "_intensity.png", "");
    dir_.write(std::string(name) + "_color.png", "");
  }
  dir_.write("a/notes.txt", "not a view");
  const auto views = calibrate::find_views({dir_.path() / "a", dir_.path() / "b"});
  ASSERT_EQ(views.size(), 3u);
  EXPECT_EQ(views[0].name, (dir_.path() / "a" / "001").string());
  EXPECT_EQ(views[1].name, (dir_.path() / "a" / "002").string());
  EXPECT_EQ(views[2].color, dir_.path() / "b" / "010_color.png");
  dir_.write("empty/readme.txt", "");
  EXPECT_THROW(calibrate::find_views({dir_.path() / "empty"}), Error);
}

}  // namespace
}  // namespace tilth::testing
