// The built plugin library tilth_registration.so, loaded as the runtime loads it: it
// provides registration.projective, which registers a frame.
#include <filesystem>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "framework/stage_registry.h"
#include "source_tree.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"

namespace tilth::registration {
namespace {

TEST(RegistrationPlugin, TheLibraryProvidesTheProjectiveStage) {
  StageRegistry registry;
  registry.load(TILTH_REGISTRATION_PLUGIN);
  const auto* entry = registry.find("registration.projective");
  ASSERT_NE(entry, nullptr);
  EXPECT_EQ(entry->plugin, "registration");

  const std::string calibration = testing::paper_rig_path().string();
  const StageContext context{"registration",
                             Params(nlohmann::json{{"calibration", calibration},
                                                   {"occlusion_tolerance_mm", 10.0},
                                                   {"interpolation", "nearest"},
                                                   {"instruction_set", "auto"},
                                                   {"roi", nullptr}}),
                             Logger("registration"),
                             {}};
  StageInstance instance = registry.create("registration.projective", context);
  auto* transform = dynamic_cast<Transform*>(instance.stage.get());
  ASSERT_NE(transform, nullptr);

  DepthImage depth;
  depth.mm = cv::Mat(480, 640, CV_32FC1, cv::Scalar(518.0f));
  ColorImage color;
  color.pixels = cv::Mat(1024, 1280, CV_8UC3, cv::Scalar(30, 120, 210));
  const std::vector<Packet> inputs = {
      Packet(FrameInfo{}, std::make_shared<const DepthImage>(std::move(depth))),
      Packet(FrameInfo{}, std::make_shared<const ColorImage>(std::move(color)))};
  std::vector<Packet> outputs(1);
  Frame frame(FrameInfo{}, inputs, outputs);
  transform->process(frame);
  const auto& registered = outputs[0].get<RegisteredColor>();
  // The principal ray at 518 mm lands at colour pixel (639.5 + 1000 * 45 / 541.97, 511.5)
  // = (722.5, 511.5): inside the image, nothing in front of it.
  EXPECT_EQ(registered.status.at<std::uint8_t>(240, 313), RegisteredColor::kValid);
  EXPECT_EQ(registered.bgr.at<cv::Vec3b>(240, 313), cv::Vec3b(30, 120, 210));
  // The last column lands beyond the colour image's right edge (u = 1362).
  EXPECT_EQ(registered.status.at<std::uint8_t>(240, 639), RegisteredColor::kOutsideColor);
}

}  // namespace
}  // namespace tilth::registration
