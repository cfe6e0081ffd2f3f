// color_window_for: the colour window the paper rig's middle half needs, worked out by
// hand; what a turned colour camera and a wide range of distances need; and the errors.
// registration_test checks that such a window registers the region as the whole image.
#include <gtest/gtest.h>

#include "color_window/region_window.h"
#include "source_tree.h"
#include "tilth/error.h"

namespace tilth {
namespace {

RigCalibration paper_rig() { return load_calibration(testing::paper_rig_path()); }

// The middle half of the depth image with the 8 rows and columns the segmentation reads.
const cv::Rect kRegion(152, 112, 336, 256);

// No distortion, R = I, T = (45, 0, 0) mm: a depth pixel (u, v) on ground d mm away
// (z = d + 23.97 mm from the ToF's optical centre) is seen at colour pixel
//   u_c = 1000 / 509.935 (u - 313.05) + 1000 * 45 / z + 639.5,
//   v_c = 1000 / 509.935 (v - 239.60) + 511.5.
// Over u 152 .. 487, v 112 .. 367 and d 400 .. 700 mm: u_c from 323.68 + 62.16 = 385.84
// (u 152, d 700) to 980.62 + 106.14 = 1086.76 (u 487, d 400), v_c from 261.27 to 761.34.
// With 2 px for sampling: x 383 .. 1089, y 259 .. 764; rounded out to 16 px: x 368 ..
// 1103, y 256 .. 767.
TEST(ColorWindow, ThePaperRigsMiddleHalfAtFourToSevenHundredMillimetres) {
  EXPECT_EQ(color_window_for(paper_rig(), kRegion, 400, 700, 16), cv::Rect(368, 256, 736, 512));
  EXPECT_EQ(color_window_for(paper_rig(), kRegion, 400, 700, 1), cv::Rect(383, 259, 707, 506));
  // Nearer ground moves the colour image's view of the region right (parallax).
  const cv::Rect near = color_window_for(paper_rig(), kRegion, 200, 200, 1);
  EXPECT_GT(near.x, 383 + 100);
}

TEST(ColorWindow, ATurnedColourCameraAndAWideRangeNeedMore) {
  RigCalibration turned = paper_rig();
  const double c = std::cos(0.1);
  const double s = std::sin(0.1);
  turned.depth_to_color_r = cv::Matx33d(c, -s, 0, s, c, 0, 0, 0, 1);  // 5.7 degrees about z
  const cv::Rect straight = color_window_for(paper_rig(), kRegion, 400, 700, 16);
  const cv::Rect window = color_window_for(turned, kRegion, 400, 700, 16);
  EXPECT_GT(window.height, straight.height + 50);  // the region's corners reach up and down
  const cv::Rect wide = color_window_for(paper_rig(), kRegion, 100, 1500, 16);
  EXPECT_EQ(wide & straight, straight);
  EXPECT_EQ(wide.x + wide.width, 1280);  // clipped to the image
}

TEST(ColorWindow, ArgumentsThatMakeNoWindowAreRefused) {
  const auto error = [](const cv::Rect& region, double near_mm, double far_mm, int step) {
    try {
      color_window_for(paper_rig(), region, near_mm, far_mm, step);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("a window");
  };
  EXPECT_EQ(error(kRegion, 700, 400, 16),
            "ground distances 700 mm to 400 mm; expected 0 < near <= far");
  EXPECT_EQ(error(kRegion, 400, 700, 0), "window step 0 px; expected >= 1");
  EXPECT_EQ(error(cv::Rect(600, 0, 100, 10), 400, 700, 16),
            "the depth region 100x10 px at (600, 0) is not inside the 640x480 px depth image");
  RigCalibration apart = paper_rig();
  apart.depth_to_color_t_mm = cv::Vec3d(5000, 0, 0);  // the colour camera 5 m to the side
  try {
    color_window_for(apart, kRegion, 400, 700, 16);
    ADD_FAILURE() << "a window for a camera that sees none of the region";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()),
              "the depth region 336x256 px at (152, 112) sees none of the colour image with the "
              "ground 400 mm to 700 mm away (calibration " +
                  testing::paper_rig_path().string() + ")");
  }
}

}  // namespace
}  // namespace tilth
