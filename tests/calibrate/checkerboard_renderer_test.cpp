// The renderer the calibration tests rely on: the corners OpenCV finds in its images are
// where the lens model projects the board's corners, with no bias, in both cameras.
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "board_views.h"
#include "test_rigs.h"

namespace tilth::testing {
namespace {

struct CornerErrors {
  double rms_px = 0.0;
  cv::Point2d mean_px;
};

CornerErrors compare(const std::vector<cv::Point2f>& found, const std::vector<cv::Point2d>& truth) {
  CornerErrors errors;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const cv::Point2d error = cv::Point2d(found[i]) - truth[i];
    errors.rms_px += error.dot(error);
    errors.mean_px += error / static_cast<double>(truth.size());
  }
  errors.rms_px = std::sqrt(errors.rms_px / truth.size());
  return errors;
}

std::vector<cv::Point2f> corners_in(const cv::Mat& gray, const Checkerboard& board) {
  std::vector<cv::Point2f> corners;
  const int flags = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_EXHAUSTIVE | cv::CALIB_CB_ACCURACY;
  EXPECT_TRUE(cv::findChessboardCornersSB(gray, board.inner_corners, corners, flags));
  return corners;
}

// Corners come back in the board's order or reversed (a 180-degree turn of the board
// leaves its grid of corners where it was): compare in the order that fits.
std::vector<cv::Point2f> in_board_order(std::vector<cv::Point2f> found,
                                        const std::vector<cv::Point2d>& truth) {
  if (cv::norm(cv::Point2d(found.front()) - truth.front()) >
      cv::norm(cv::Point2d(found.back()) - truth.front())) {
    std::reverse(found.begin(), found.end());
  }
  return found;
}

TEST(CheckerboardRenderer, CornersLandWhereTheLensModelProjectsThem) {
  const RigCalibration rig = rotated_rig();
  const Checkerboard board;
  const auto poses = calibration_poses(rig, board, 6, 7);
  ASSERT_EQ(poses.size(), 6u);
  cv::RNG rng(3);
  cv::Point2d depth_mean;
  cv::Point2d color_mean;
  for (const auto& pose : poses) {
    const cv::Mat intensity = render_tof_intensity(rig, board, pose, rng);
    const cv::Mat mosaic = render_color_bayer_rg(rig, board, pose, rng);
    ASSERT_EQ(intensity.type(), CV_16UC1);
    ASSERT_EQ(mosaic.type(), CV_8UC1);
    cv::Mat gray;
    cv::cvtColor(mosaic, gray, cv::COLOR_BayerBG2GRAY);
    const auto depth_truth = projected_corners(rig, board, pose, false);
    const auto color_truth = projected_corners(rig, board, pose, true);
    const auto depth = compare(
        in_board_order(corners_in(calibrate::intensity_to_8bit(intensity), board), depth_truth),
        depth_truth);
    const auto color = compare(in_board_order(corners_in(gray, board), color_truth), color_truth);
    // OpenCV's corner detector reaches 0.05 to 0.2 px on these noisy images (measured:
    // at most 0.2 px RMS in a view); 0.25 px bounds that without hiding an error of the
    // renderer, which would be a whole pixel or a systematic shift.
    EXPECT_LT(depth.rms_px, 0.25);
    EXPECT_LT(color.rms_px, 0.25);
    depth_mean += depth.mean_px / static_cast<double>(poses.size());
    color_mean += color.mean_px / static_cast<double>(poses.size());
  }
  // A shift common to all views (a half-pixel convention wrong somewhere) would move the
  // principal points. Single views' means scatter by up to 0.15 px (a steep board); over
  // the views, measured below 0.02 px. 0.04 px is a tenth of what would matter.
  EXPECT_LT(cv::norm(depth_mean), 0.04) << depth_mean;
  EXPECT_LT(cv::norm(color_mean), 0.04) << color_mean;
}

TEST(CheckerboardRenderer, PosesCoverTheCornersOfTheToFImage) {
  const RigCalibration rig = rotated_rig();
  const Checkerboard board;
  const auto poses = calibration_poses(rig, board, 18, 1);
  ASSERT_EQ(poses.size(), 18u);
  // Each quadrant of the ToF image holds the centre of at least 3 boards: the corners
  // of the image are where distortion and the principal point are determined.
  int quadrants[2][2] = {};
  for (const auto& pose : poses) {
    EXPECT_TRUE(board_inside_both(rig, board, pose, 4.0));
    const auto corners = projected_corners(rig, board, pose, false);
    const cv::Point2d centre = (corners.front() + corners.back()) / 2.0;
    ++quadrants[centre.y > rig.depth.height / 2.0][centre.x > rig.depth.width / 2.0];
  }
  for (const auto& row : quadrants) {
    for (const int count : row) EXPECT_GE(count, 3);
  }
}

}  // namespace
}  // namespace tilth::testing
