// The built plugin library tilth_depth.so, loaded as the runtime loads it: it provides
// depth.projection, which projects a frame, and a bad calibration stops it with the node
// and the field named.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "calibration_file.h"
#include "framework/stage_registry.h"
#include "source_tree.h"
#include "tilth/error.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/raw_tof_frame.h"

namespace tilth::depth {
namespace {

namespace fs = std::filesystem;

const fs::path kPaperRig = testing::paper_rig_path();

StageContext context_for(const fs::path& calibration) {
  return {"depth",
          Params(nlohmann::json{{"calibration", calibration.string()}, {"saturated_gray", 65535}}),
          Logger("depth"),
          {}};
}

TEST(DepthPlugin, TheLibraryProvidesTheProjectionStage) {
  StageRegistry registry;
  registry.load(TILTH_DEPTH_PLUGIN);
  const auto* entry = registry.find("depth.projection");
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->plugin, "depth");

  StageInstance instance = registry.create("depth.projection", context_for(kPaperRig));
  auto* transform = dynamic_cast<Transform*>(instance.stage.get());
  ASSERT_NE(transform, nullptr);
  RawTofFrame raw;
  raw.gray = cv::Mat(480, 640, CV_16UC1, cv::Scalar(23666));
  const Packet input(FrameInfo{}, std::make_shared<const RawTofFrame>(raw));
  std::vector<Packet> outputs(1);
  Frame frame(FrameInfo{}, std::span<const Packet>(&input, 1), outputs);
  transform->process(frame);
  // Eq. 1 at pixel (313, 240): 23666 * 0.0229 / sqrt(((313 - 313.05)^2 + (240 - 239.6)^2)
  // / 509.935^2 + 1) - 23.97 = 517.98123 mm; float32 arithmetic stays within 1e-3 mm.
  EXPECT_NEAR(outputs[0].get<DepthImage>().mm.at<float>(240, 313), 517.98123, 1e-3);
}

TEST(DepthPlugin, ABadCalibrationStopsTheNodeWithTheFieldNamed) {
  nlohmann::json rig = testing::paper_rig_document();
  rig["depth_camera"]["fx"] = 0;
  const testing::CalibrationFile file(rig);
  StageRegistry registry;
  registry.load(TILTH_DEPTH_PLUGIN);
  try {
    registry.create("depth.projection", context_for(file.path()));
    ADD_FAILURE() << "the stage started";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "node 'depth' (depth.projection) failed to start: " + file.path().string() +
                  ":/depth_camera/fx: expected a number > 0, got 0");
  }
}

}  // namespace
}  // namespace tilth::depth
