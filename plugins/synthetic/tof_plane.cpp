// A ToF camera looking straight down at flat soil: raw 16-bit gray frames of a plane at
// a known distance, by inverting the paper's eq. 1 (radial measurement, gray = d / mu),
// with Gaussian range noise. Defaults are the paper's blaze-101 values.
#include <chrono>
#include <cmath>

#include <opencv2/core.hpp>

#include "tilth/messages/raw_tof_frame.h"
#include "tilth/playback_clock.h"
#include "tilth/plugin.h"

namespace tilth::synthetic {
namespace {

class TofPlane final : public Source {
 public:
  explicit TofPlane(const StageContext& context)
      : frames_(context.params.integer("frames")),
        clock_(context.params.number("fps") > 0 ? 1.0 : 0.0),
        pace_ns_(context.params.number("fps") > 0 ? 1e9 / context.params.number("fps") : 0.0),
        noise_(static_cast<std::uint64_t>(context.params.integer("seed"))) {
    const double f = context.params.number("focal_px");
    const double cx = context.params.number("cx");
    const double cy = context.params.number("cy");
    const double mu = context.params.number("gray_to_mm");
    const double optical_centre_depth =
        context.params.number("distance_mm") + context.params.number("z_offset_mm");
    // Radial distance per pixel, computed once: d = Z * sqrt(x'^2 + y'^2 + 1).
    gray_mean_.create(static_cast<int>(context.params.integer("height")),
                      static_cast<int>(context.params.integer("width")), CV_32FC1);
    for (int v = 0; v < gray_mean_.rows; ++v) {
      for (int u = 0; u < gray_mean_.cols; ++u) {
        const double x = (u - cx) / f;
        const double y = (v - cy) / f;
        gray_mean_.at<float>(v, u) =
            static_cast<float>(optical_centre_depth * std::sqrt(x * x + y * y + 1.0) / mu);
      }
    }
    noise_gray_ = context.params.number("noise_mm") / mu;
  }

  bool produce(Frame& frame) override {
    if (frames_ > 0 && index_ >= static_cast<std::uint64_t>(frames_)) return false;
    if (!clock_.wait(static_cast<std::int64_t>(static_cast<double>(index_) * pace_ns_))) {
      return false;
    }
    cv::Mat gray_float = gray_mean_.clone();
    if (noise_gray_ > 0) {
      cv::Mat noise(gray_float.size(), CV_32FC1);
      noise_.fill(noise, cv::RNG::NORMAL, 0.0, noise_gray_);
      gray_float += noise;
    }
    RawTofFrame raw;
    gray_float.convertTo(raw.gray, CV_16UC1);  // rounds and saturates
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    const auto now_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now).count();
    frame.set_capture(index_, now_ns, now_ns);
    frame.emit(0, std::move(raw));
    ++index_;
    return true;
  }

  void interrupt() override { clock_.interrupt(); }

 private:
  const std::int64_t frames_;
  PlaybackClock clock_;
  const double pace_ns_;  // between frames, at the `fps` parameter
  cv::RNG noise_;
  cv::Mat gray_mean_;
  double noise_gray_ = 0.0;
  std::uint64_t index_ = 0;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "synthetic.tof_plane";
  d.summary = "raw ToF frames of flat soil at a known distance (paper eq. 1 inverted)";
  d.outputs = {PortSpec::of<RawTofFrame>("raw", "16-bit gray, radial distance / gray_to_mm")};
  d.params = {
      ParamSpec::number("distance_mm", 518.0)
          .range(50, 5000)
          .in_unit("mm")
          .describe("mounting surface to the plane, along the optical axis"),
      ParamSpec::number("noise_mm", 1.0)
          .range(0, 100)
          .in_unit("mm")
          .describe("standard deviation of the range noise"),
      ParamSpec::integer("frames", 0)
          .range(0, std::nullopt)
          .describe("frames to produce; 0 = endless"),
      ParamSpec::number("fps", 30.0)
          .range(0, 1000)
          .in_unit("1/s")
          .describe("frame rate; 0 = as fast as possible"),
      ParamSpec::integer("seed", 1).range(0, std::nullopt).describe("noise seed"),
      ParamSpec::integer("width", 640).range(1, 8192).in_unit("px").describe("image width"),
      ParamSpec::integer("height", 480).range(1, 8192).in_unit("px").describe("image height"),
      ParamSpec::number("focal_px", 509.935)
          .range(1, std::nullopt)
          .in_unit("px")
          .describe("focal length"),
      ParamSpec::number("cx", 313.05).in_unit("px").describe("principal point, x"),
      ParamSpec::number("cy", 239.60).in_unit("px").describe("principal point, y"),
      ParamSpec::number("gray_to_mm", 0.0229)
          .range(1e-6, std::nullopt)
          .in_unit("mm")
          .describe("millimetres per gray value (the paper's mu)"),
      ParamSpec::number("z_offset_mm", 23.97)
          .in_unit("mm")
          .describe("optical centre behind the mounting surface"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<TofPlane>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::synthetic
