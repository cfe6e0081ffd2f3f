// depth.projection, per docs/formats/calibration.md (paper eq. 1 for a radial measurement):
//   d = g * gray_to_mm + gray_offset_mm      (the camera's own scale/offset win)
//   z = d * factor(u, v) - z_offset_mm       factor = 1 / sqrt(x'^2 + y'^2 + 1) (radial)
//                                            factor = 1                       (z)
// with (x', y') the undistorted normalised coordinates of pixel (u, v). The factor
// depends on the calibration only, so it is an image computed once in the constructor
// and a frame costs two multiply-adds per pixel, eight pixels at a time. Gray 0 (no
// measurement) and gray at or above `saturated_gray` (the sensor's ceiling: saturated, or
// beyond its range) -> NaN: neither says where the surface is.
#include "projection.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>

#include <opencv2/core.hpp>

#include "camera_geometry/lens_model.h"
#include "tilth/calibration.h"
#include "tilth/error.h"
#include "tilth/frame_calibration.h"
#include "tilth/message_pool.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/plugin.h"

namespace tilth::depth {
namespace {

// Eight pixels at a time in GCC vector extensions: eight grays (16 bytes) widened to
// floats, then computed as two vectors of four, which fit an SSE2 register. (GCC splits
// wider vectors' arithmetic into registers, but their comparisons into single lanes.)
constexpr int kLanes = 8;
using Grays = std::uint16_t __attribute__((vector_size(kLanes * sizeof(std::uint16_t))));
using EightFloats = float __attribute__((vector_size(kLanes * sizeof(float))));
using Floats = float __attribute__((vector_size(4 * sizeof(float))));

cv::Mat range_to_depth_factor(const DepthCameraCalibration& camera, const std::string& file) {
  if (camera.depth_measure == DepthMeasure::kZ) {
    return cv::Mat(camera.height, camera.width, CV_32FC1, cv::Scalar(1.0));
  }
  const cv::Mat normalised =
      lens::undistorted_pixel_grid(camera, file + ":/depth_camera/distortion");
  cv::Mat factor(camera.height, camera.width, CV_32FC1);
  for (int v = 0; v < camera.height; ++v) {
    const auto* xy = normalised.ptr<cv::Vec2d>(v);
    auto* out = factor.ptr<float>(v);
    for (int u = 0; u < camera.width; ++u) {
      out[u] = static_cast<float>(1.0 / std::sqrt(xy[u][0] * xy[u][0] + xy[u][1] * xy[u][1] + 1.0));
    }
  }
  return factor;
}

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

// What a frame's projection needs from its calibration.
struct Projection {
  DepthCameraCalibration camera;
  cv::Mat factor;  // CV_32FC1, see the top of the file
};

class DepthProjection final : public Transform {
 public:
  explicit DepthProjection(const StageContext& context)
      : calibration_(context.params, context.log,
                     [](const RigCalibration& rig) {
                       return Projection{rig.depth, range_to_depth_factor(rig.depth, rig.origin)};
                     }),
        saturated_gray_(static_cast<std::uint16_t>(context.params.integer("saturated_gray"))) {}

  void process(Frame& frame) override {
    const auto& raw = frame.input<RawTofFrame>(0);
    const auto used = calibration_.for_frame(raw.rig);
    const DepthCameraCalibration& camera = used->derived.camera;
    if (raw.gray.type() != CV_16UC1) {
      throw Error("raw ToF frame has pixel type " + cv::typeToString(raw.gray.type()) +
                  "; expected CV_16UC1 (16-bit gray)");
    }
    if (raw.gray.cols != camera.width || raw.gray.rows != camera.height) {
      throw Error("raw ToF frame is " + size_text(raw.gray.cols, raw.gray.rows) +
                  " px but the calibration " + used->rig->origin + " is for " +
                  size_text(camera.width, camera.height) + " px");
    }
    const auto scale = static_cast<float>(raw.scale_mm.value_or(camera.gray_to_mm));
    const auto offset = static_cast<float>(raw.offset_mm.value_or(camera.gray_offset_mm));
    const auto z_offset = static_cast<float>(camera.z_offset_mm);
    constexpr float kNoDepth = std::numeric_limits<float>::quiet_NaN();
    const auto project = [&](std::uint16_t gray, float factor) {
      return gray == 0 || gray >= saturated_gray_
                 ? kNoDepth
                 : (static_cast<float>(gray) * scale + offset) * factor - z_offset;
    };
    const Floats scale4 = Floats{} + scale;
    const Floats offset4 = Floats{} + offset;
    const Floats z_offset4 = Floats{} + z_offset;
    const Floats saturated4 = Floats{} + static_cast<float>(saturated_gray_);
    const Floats no_depth4 = Floats{} + kNoDepth;
    const auto project4 = [=](const Floats& g, const float* factor4, float* z4) {
      Floats factors;
      std::memcpy(&factors, factor4, sizeof factors);
      const Floats z = (g * scale4 + offset4) * factors - z_offset4;
      const Floats out = (g == Floats{}) | (g >= saturated4) ? no_depth4 : z;
      std::memcpy(z4, &out, sizeof out);
    };
    const auto project8 = [=](const std::uint16_t* gray8, const float* factor8, float* z8) {
      Grays grays;
      std::memcpy(&grays, gray8, sizeof grays);
      const EightFloats g = __builtin_convertvector(grays, EightFloats);
      project4(__builtin_shufflevector(g, g, 0, 1, 2, 3), factor8, z8);
      project4(__builtin_shufflevector(g, g, 4, 5, 6, 7), factor8 + 4, z8 + 4);
    };

    auto depth = pool_.acquire();
    depth->rig = used->rig;
    reuse_or_create(depth->mm, camera.height, camera.width, CV_32FC1);
    const bool one_row = raw.gray.isContinuous() && depth->mm.isContinuous();
    const int rows = one_row ? 1 : camera.height;
    const int cols = one_row ? camera.height * camera.width : camera.width;
    for (int v = 0; v < rows; ++v) {
      const auto* gray = raw.gray.ptr<std::uint16_t>(v);
      const auto* factor = used->derived.factor.ptr<float>(v);
      auto* z = depth->mm.ptr<float>(v);
      int u = 0;
      for (; u + kLanes <= cols; u += kLanes) project8(gray + u, factor + u, z + u);
      for (; u < cols; ++u) z[u] = project(gray[u], factor[u]);
    }
    frame.set_output(0, std::move(depth));
  }

 private:
  FrameCalibration<Projection> calibration_;
  const std::uint16_t saturated_gray_;
  MessagePool<DepthImage> pool_;
};

}  // namespace

StageDescriptor describe_projection() {
  StageDescriptor d;
  d.type = "depth.projection";
  d.summary =
      "raw ToF gray -> depth in mm from the mounting surface along the optical axis (eq. 1)";
  d.inputs = {PortSpec::of<RawTofFrame>("raw", "16-bit gray; 0 = no measurement")};
  d.outputs = {PortSpec::of<DepthImage>("depth", "mm from the mounting surface; NaN = no depth")};
  d.params = {
      frame_calibration_param(),
      ParamSpec::integer("saturated_gray", 65535)
          .range(1, 65535)
          .describe("gray at or above this is saturated or beyond range: no depth"),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<DepthProjection>();
  return d;
}

TILTH_STAGE(describe_projection());

}  // namespace tilth::depth
