// tilth calibrate color-window: the window and the features that make the camera read it
// out, as color_window_for computes them (tests/libs/color_window_test.cpp checks that),
// and its usage errors.
#include <gtest/gtest.h>

#include "source_tree.h"
#include "test_rigs.h"

namespace tilth::testing {
namespace {

TEST(ColorWindowCommand, PrintsTheWindowAndTheFeaturesThatSetIt) {
  const ToolRun run =
      run_calibrate("color-window " + paper_rig_path().string() + " --distance-mm 400:700");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.output,
            "region \"middle_half\": depth x 152..487, y 112..367 with the 8 px the "
            "segmentation reads\n"
            "colour window for ground 400 to 700 mm away: 736x512 px at (368, 256), 29 % of the "
            "1280x1024 px image\n"
            "\"features\": [{\"Width\": 736}, {\"Height\": 512}, {\"OffsetX\": 368}, "
            "{\"OffsetY\": 256}]\n");
  const ToolRun corner =
      run_calibrate("color-window " + paper_rig_path().string() +
                    " --distance-mm 400:700 --step 2 --roi '{\"x\": 0, \"y\": 0, \"width\": "
                    "100, \"height\": 50}'");
  EXPECT_EQ(corner.exit_code, 0) << corner.output;
  EXPECT_NE(corner.output.find("262x120 px at (84, 38)"), std::string::npos) << corner.output;
}

TEST(ColorWindowCommand, UsageErrorsSayWhatWasExpected) {
  const std::string rig = paper_rig_path().string();
  for (const auto& [args, message] : std::vector<std::pair<std::string, std::string>>{
           {"color-window " + rig, "color-window needs --distance-mm NEAR:FAR"},
           {"color-window " + rig + " --distance-mm 700:400",
            "--distance-mm: expected NEAR:FAR in mm with 0 < NEAR <= FAR (e.g. 400:700), got "
            "'700:400'"},
           {"color-window " + rig + " --distance-mm 400:700 --step 0",
            "--step: expected a whole number in [2, 1024], got '0'"},
           {"color-window " + rig + " --distance-mm 400:700 --step 3",
            "--step: expected an even number of px (a Bayer mosaic keeps the pattern its pixel "
            "format names only at even offsets), got 3"},
           {"color-window --distance-mm 400:700",
            "color-window takes RIG.calib.json and --distance-mm NEAR:FAR"},
           {"color-window " + rig + " --distance-mm 400:700 --views 3",
            "--views is not a color-window option"}}) {
    const ToolRun run = run_calibrate(args);
    EXPECT_EQ(run.exit_code, 2) << args;
    EXPECT_EQ(run.output.substr(0, run.output.find('\n')), "tilth calibrate: " + message) << args;
  }
}

}  // namespace
}  // namespace tilth::testing
