#include "mask_registration.h"

#include <vector>

#include "stage_in_process.h"
#include "tilth/frame.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::tools {

// Both stages use the calibration each frame carries ("calibration": "", the default).
MaskRegistration::MaskRegistration(const StageRegistry& registry)
    : projection_(make_stage(registry, "depth.projection", nlohmann::json::object())),
      registration_(
          make_stage(registry, "registration.projective", {{"interpolation", "nearest"}})) {}

cv::Mat MaskRegistration::to_depth_grid(const cv::Mat& depth_gray,
                                        const std::shared_ptr<const RigCalibration>& rig,
                                        const cv::Mat& color_classes, std::uint64_t frame_id) {
  FrameInfo info;
  info.frame_id = frame_id;
  auto raw = std::make_shared<RawTofFrame>();
  raw->gray = depth_gray;
  raw->rig = rig;
  std::vector<Packet> depth(1);
  const std::vector<Packet> projecting{Packet(info, std::move(raw))};
  Frame projection(info, projecting, depth);
  stage_as<Transform>(projection_, "depth.projection").process(projection);

  // The classes as a mono8 image: nearest sampling copies a pixel's value unchanged.
  auto classes = std::make_shared<ColorImage>();
  classes->pixels = color_classes;
  classes->format = PixelFormat::kMono8;
  std::vector<Packet> registered(1);
  const std::vector<Packet> registering{depth[0], Packet(info, std::move(classes))};
  Frame registration(info, registering, registered);
  stage_as<Transform>(registration_, "registration.projective").process(registration);

  const auto& color = registered[0].get<RegisteredColor>();
  cv::Mat mask(color.status.size(), CV_8UC1, cv::Scalar(ResidueMask::kUnknown));
  for (int v = 0; v < mask.rows; ++v) {
    const auto* status = color.status.ptr<std::uint8_t>(v);
    const auto* bgr = color.bgr.ptr<std::uint8_t>(v);
    auto* out = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < mask.cols; ++u) {
      if (status[u] == RegisteredColor::kValid) out[u] = bgr[3 * u + 1];
    }
  }
  return mask;
}

}  // namespace tilth::tools
