// The scene simulator as a source: ToF raw frames and colour frames of soil with crop
// residue, rendered by ray casting a SoilScene from each camera's own pose in the rig
// calibration, with the ground truth (distance and residue mask) of every frame.
//
// ToF: each pixel casts four rays over its footprint; where they meet different
// surfaces (straw edges) the pixel reports their mean range, the mixed pixel a real ToF
// camera produces, and sometimes drops out; elsewhere it reports its centre ray exactly.
// Range noise grows with the square of the range (and, when the preset says so, as the
// surface reflects less); multipath lengthens the range near standing residue; values are
// quantised to 16-bit gray.
// Colour: reflectance times sun and sky light (with shadows) plus sensor noise, optionally
// as a Bayer mosaic. Static presets are rendered once and re-noised per frame; moving ground
// is rendered per frame.
#include <cmath>
#include <optional>
#include <string>

#include <opencv2/imgproc.hpp>

#include "camera_geometry/lens_model.h"
#include "preset_changes.h"
#include "ray_caster.h"
#include "scene_preset.h"
#include "tilth/calibration.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/ground_truth.h"
#include "tilth/messages/raw_tof_frame.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/playback_clock.h"
#include "tilth/plugin.h"
#include "tilth/replay_host_time.h"

namespace tilth::synthetic {
namespace {

constexpr double kSimulatedCameraFps = 30.0;
constexpr std::int64_t kStartNs = 1'000'000'000;
constexpr std::int64_t kColorLagNs = 400'000;  // the colour camera fires 0.4 ms later
// The reflectance at which `noise_mm` holds when the noise depends on reflectance.
constexpr double kReferenceReflectance = 0.4;

// Normalised, undistorted ray directions (z = 1) of pixel positions of a camera, CV_32FC2;
// `where` names the calibration's distortion in an error.
cv::Mat ray_directions(const CameraIntrinsics& camera, const std::vector<cv::Point2d>& pixels,
                       const std::string& where) {
  cv::Mat rays;
  cv::Mat(lens::undistort(camera, pixels, where), false).convertTo(rays, CV_32FC2);
  return rays;
}

int bayer_code(PixelFormat format) {
  // OpenCV names Bayer patterns by the second row's first two pixels; we mosaic by hand.
  switch (format) {
    case PixelFormat::kBayerRggb8:
      return 0;
    case PixelFormat::kBayerGrbg8:
      return 1;
    case PixelFormat::kBayerGbrg8:
      return 2;
    default:
      return 3;  // bggr
  }
}

// Which BGR channel the mosaic keeps at (row, col) for each pattern.
int mosaic_channel(int pattern, int row, int col) {
  static const int kChannels[4][2][2] = {
      {{2, 1}, {1, 0}},  // RG/GB
      {{1, 2}, {0, 1}},  // GR/BG
      {{1, 0}, {2, 1}},  // GB/RG
      {{0, 1}, {1, 2}},  // BG/GR
  };
  return kChannels[pattern][row & 1][col & 1];
}

class SceneSource final : public Source {
 public:
  enum Port { kRaw = 0, kColor = 1, kTruth = 2 };

  explicit SceneSource(const StageContext& context)
      : rig_(load_calibration(context.params.path("calibration"))),
        carried_rig_(std::make_shared<const RigCalibration>(rig_)),
        preset_(changed_preset(scene_preset(context.params.string("preset")),
                               context.params.json("scene"))),
        lighting_(preset_),
        seed_(static_cast<std::uint64_t>(context.params.integer("seed"))),
        frames_(context.params.integer("frames") > 0 ? context.params.integer("frames")
                                                     : preset_.frames),
        clock_(context.params.number("fps") > 0 ? 1.0 : 0.0),
        pace_ns_(context.params.number("fps") > 0 ? 1e9 / context.params.number("fps") : 0.0),
        host_time_(context.params),
        noise_mm_at_500_(context.params.number("noise_mm")),
        dropout_(context.params.number("dropout")),
        color_noise_(context.params.number("color_noise")),
        format_(*parse_pixel_format(context.params.string("color_format"))),
        index_(context.params.integer("first_frame")) {
    const double distance = context.params.number("ground_distance_mm") > 0
                                ? context.params.number("ground_distance_mm")
                                : preset_.ground_distance_mm;
    preset_.ground_distance_mm = distance;
    soil_z_ = distance + rig_.depth.z_offset_mm;
    prepare_rays();
    const double margin = 60.0;
    const double half_width =
        soil_z_ * std::max(rig_.depth.cx, rig_.depth.width - rig_.depth.cx) / rig_.depth.fx +
        std::abs(rig_.depth_to_color_t_mm[0]) + margin;
    const double half_height =
        soil_z_ * std::max(rig_.depth.cy, rig_.depth.height - rig_.depth.cy) / rig_.depth.fy +
        std::abs(rig_.depth_to_color_t_mm[1]) + margin;
    const cv::Rect2d area(-half_width, -half_height, 2 * half_width + preset_.track_length_mm,
                          2 * half_height);
    const double cell_mm = preset_.track_length_mm > 0 ? 1.0 : 0.5;
    scene_ = std::make_unique<SoilScene>(preset_, soil_z_, area, cell_mm, seed_);
    if (preset_.speed_mm_per_s == 0.0) render(0.0);
  }

  bool produce(Frame& frame) override {
    if (index_ >= first_frame_ + frames_) return false;
    if (!clock_.wait(static_cast<std::int64_t>(static_cast<double>(index_) * pace_ns_))) {
      return false;
    }
    const double shift = preset_.speed_mm_per_s * static_cast<double>(index_) / kSimulatedCameraFps;
    if (preset_.speed_mm_per_s != 0.0) render(shift);
    cv::RNG rng(seed_ * 1'000'003 + static_cast<std::uint64_t>(index_));

    const std::int64_t device_ns =
        kStartNs +
        static_cast<std::int64_t>(static_cast<double>(index_) * 1e9 / kSimulatedCameraFps);
    RawTofFrame raw = tof_frame(rng);
    raw.device_timestamp_ns = device_ns;
    raw.rig = carried_rig_;
    ColorImage color = color_frame(rng);
    color.device_timestamp_ns = device_ns + kColorLagNs;
    GroundTruth truth;
    truth.distance_mm = soil_z_ - scene_->ground_height_mm(shift, 0.0) - rig_.depth.z_offset_mm;
    truth.residue_mask = truth_mask_.clone();

    // Simulated host times follow the device clock from the first frame's host time.
    if (!host_clock_at_device_zero_ns_) {
      host_clock_at_device_zero_ns_ = host_time_.stamp(std::nullopt) - device_ns;
    }
    const std::int64_t host_ns = host_time_.stamp(*host_clock_at_device_zero_ns_ + device_ns);
    frame.set_capture(static_cast<std::uint64_t>(index_), device_ns, host_ns);
    frame.emit(kRaw, std::move(raw));
    frame.emit(kColor, std::move(color));
    frame.emit(kTruth, std::move(truth));
    ++index_;
    return true;
  }

  void interrupt() override { clock_.interrupt(); }

 private:
  void prepare_rays() {
    std::vector<cv::Point2d> centres;
    std::vector<cv::Point2d> corners;
    for (int v = 0; v < rig_.depth.height; ++v) {
      for (int u = 0; u < rig_.depth.width; ++u) {
        centres.emplace_back(u, v);
        for (const double dv : {-0.25, 0.25}) {
          for (const double du : {-0.25, 0.25}) corners.emplace_back(u + du, v + dv);
        }
      }
    }
    const std::string depth_distortion = rig_.origin + ":/depth_camera/distortion";
    tof_centre_rays_ = ray_directions(rig_.depth, centres, depth_distortion);
    tof_corner_rays_ = ray_directions(rig_.depth, corners, depth_distortion);
    std::vector<cv::Point2d> colour_pixels;
    for (int v = 0; v < rig_.color.height; ++v) {
      for (int u = 0; u < rig_.color.width; ++u) colour_pixels.emplace_back(u, v);
    }
    colour_rays_ =
        ray_directions(rig_.color, colour_pixels, rig_.origin + ":/color_camera/distortion");
    // The colour camera in the ToF frame: P_d = R^T (P_c - T).
    colour_rotation_ = rig_.depth_to_color_r.t();
    colour_origin_ = -(colour_rotation_ * rig_.depth_to_color_t_mm);
  }

  // Noise-free range, material mix and light for the ground shifted by `shift`.
  void render(double shift) {
    const int width = rig_.depth.width;
    range_mm_.create(rig_.depth.height, width, CV_32FC1);
    mixed_.create(rig_.depth.height, width, CV_8UC1);
    reflectance_.create(rig_.depth.height, width, CV_32FC1);
    truth_mask_.create(rig_.depth.height, width, CV_8UC1);
    const cv::Vec3d tof_origin(0, 0, 0);
    cv::parallel_for_(cv::Range(0, rig_.depth.height), [&](const cv::Range& rows) {
      for (int v = rows.start; v < rows.end; ++v) {
        for (int u = 0; u < width; ++u) {
          const int index = v * width + u;
          int residue = 0;
          double sum = 0.0;
          double nearest = 1e9;
          double farthest = 0.0;
          double reflectance = 0.0;
          for (int k = 0; k < 4; ++k) {
            const cv::Vec2f ray = tof_corner_rays_.at<cv::Vec2f>(index * 4 + k);
            const SurfaceHit hit = cast_ray(*scene_, tof_origin, {ray[0], ray[1], 1.0}, shift);
            residue += hit.material != Material::kSoil;
            sum += measured(hit);
            const cv::Vec3f albedo = scene_->albedo(hit.x_mm, hit.y_mm);
            reflectance += (albedo[0] + albedo[1] + albedo[2]) / 12.0;
            nearest = std::min(nearest, hit.range_mm);
            farthest = std::max(farthest, hit.range_mm);
          }
          double range = sum / 4.0;
          if (residue == 0 && farthest - nearest < 2.0) {
            const cv::Vec2f ray = tof_centre_rays_.at<cv::Vec2f>(index);
            range = measured(cast_ray(*scene_, tof_origin, {ray[0], ray[1], 1.0}, shift));
          }
          range_mm_.at<float>(v, u) = static_cast<float>(range);
          reflectance_.at<float>(v, u) = static_cast<float>(reflectance);
          mixed_.at<std::uint8_t>(v, u) = farthest - nearest > 10.0;
          truth_mask_.at<std::uint8_t>(v, u) = residue == 0   ? ResidueMask::kSoil
                                               : residue == 4 ? ResidueMask::kResidue
                                                              : ResidueMask::kUnknown;
        }
      }
    });
    const int colour_width = rig_.color.width;
    radiance_.create(rig_.color.height, colour_width, CV_32FC3);
    cv::parallel_for_(cv::Range(0, rig_.color.height), [&](const cv::Range& rows) {
      for (int v = rows.start; v < rows.end; ++v) {
        for (int u = 0; u < colour_width; ++u) {
          const cv::Vec2f ray = colour_rays_.at<cv::Vec2f>(v * colour_width + u);
          cv::Vec3d direction = colour_rotation_ * cv::Vec3d(ray[0], ray[1], 1.0);
          direction /= direction[2];
          const SurfaceHit hit = cast_ray(*scene_, colour_origin_, direction, shift);
          radiance_.at<cv::Vec3f>(v, u) =
              scene_->albedo(hit.x_mm, hit.y_mm).mul(sunlight(*scene_, hit, lighting_));
        }
      }
    });
  }

  // What the ToF camera measures along a ray: the range (radial) or its z, lengthened by
  // the light that reaches the hit by way of residue standing near it.
  double measured(const SurfaceHit& hit) const {
    const double multipath = preset_.multipath * scene_->clutter_mm(hit.x_mm, hit.y_mm);
    return (rig_.depth.depth_measure == DepthMeasure::kRadial ? hit.range_mm : hit.z_mm) +
           multipath;
  }

  RawTofFrame tof_frame(cv::RNG& rng) const {
    RawTofFrame raw;
    raw.gray.create(range_mm_.size(), CV_16UC1);
    const double mu = rig_.depth.gray_to_mm;
    for (int v = 0; v < range_mm_.rows; ++v) {
      for (int u = 0; u < range_mm_.cols; ++u) {
        const double range = range_mm_.at<float>(v, u);
        const double dimness =
            preset_.reflectivity_noise
                ? std::sqrt(kReferenceReflectance /
                            std::max(0.05, static_cast<double>(reflectance_.at<float>(v, u))))
                : 1.0;
        const double sigma = noise_mm_at_500_ * (range / 500.0) * (range / 500.0) * dimness;
        const bool drop = rng.uniform(0.0, 1.0) < dropout_ ||
                          (mixed_.at<std::uint8_t>(v, u) && rng.uniform(0.0, 1.0) < 0.2);
        const double gray = (range + rng.gaussian(sigma) - rig_.depth.gray_offset_mm) / mu;
        raw.gray.at<std::uint16_t>(v, u) =
            drop ? 0 : cv::saturate_cast<std::uint16_t>(std::max(1.0, std::round(gray)));
      }
    }
    return raw;
  }

  ColorImage color_frame(cv::RNG& rng) const {
    cv::Mat noise(radiance_.size(), CV_32FC3);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, color_noise_);
    cv::Mat bgr;
    cv::Mat(radiance_ * 255.0 + noise).convertTo(bgr, CV_8UC3);
    ColorImage color;
    color.format = format_;
    if (format_ == PixelFormat::kBgr8) {
      color.pixels = bgr;
      return color;
    }
    const int pattern = bayer_code(format_);
    color.pixels.create(bgr.size(), CV_8UC1);
    for (int r = 0; r < bgr.rows; ++r) {
      for (int c = 0; c < bgr.cols; ++c) {
        color.pixels.at<std::uint8_t>(r, c) =
            bgr.at<cv::Vec3b>(r, c)[mosaic_channel(pattern, r, c)];
      }
    }
    return color;
  }

  const RigCalibration rig_;
  const std::shared_ptr<const RigCalibration> carried_rig_;  // the frames carry it
  ScenePreset preset_;
  const Lighting lighting_;
  const std::uint64_t seed_;
  const std::int64_t frames_;
  PlaybackClock clock_;
  const double pace_ns_;  // between frames, at the `fps` parameter
  const ReplayHostTime host_time_;
  std::optional<std::int64_t> host_clock_at_device_zero_ns_;
  const double noise_mm_at_500_;
  const double dropout_;
  const double color_noise_;
  const PixelFormat format_;
  double soil_z_ = 0.0;
  std::unique_ptr<SoilScene> scene_;
  cv::Mat tof_centre_rays_;  // CV_32FC2 per pixel
  cv::Mat tof_corner_rays_;  // CV_32FC2, four per pixel
  cv::Mat colour_rays_;      // CV_32FC2 per colour pixel, in the colour camera frame
  cv::Matx33d colour_rotation_;
  cv::Vec3d colour_origin_;
  cv::Mat range_mm_;     // CV_32F: noise-free measured range
  cv::Mat mixed_;        // CV_8U: 1 where the footprint spans surfaces > 10 mm apart
  cv::Mat reflectance_;  // CV_32F: mean reflectance over the footprint
  cv::Mat truth_mask_;   // CV_8U: ResidueMask values
  cv::Mat radiance_;     // CV_32FC3: reflectance x light
  std::int64_t index_;
  const std::int64_t first_frame_ = index_;
};

StageDescriptor describe() {
  StageDescriptor d;
  d.type = "synthetic.scene";
  d.summary = "simulated ToF + colour frames of soil with crop residue, with ground truth";
  d.outputs = {PortSpec::of<RawTofFrame>("raw", "ToF gray frames"),
               PortSpec::of<ColorImage>("color", "colour frames"),
               PortSpec::of<GroundTruth>("truth", "true ground distance and residue mask")};
  d.params = {
      ParamSpec::path("calibration", std::nullopt).describe("rig calibration: both cameras' poses"),
      ParamSpec::choice("preset", scene_preset_names(), "case_c").describe("scene preset"),
      ParamSpec::json("scene", nlohmann::json::object())
          .describe("fields of the preset to change, e.g. {\"straws\": 600, \"soil_bgr\": "
                    "[0.2, 0.25, 0.3]} (docs/simulator.md, \"Scenes of your own\")"),
      ParamSpec::integer("seed", 1).range(0, std::nullopt).describe("scene and noise seed"),
      ParamSpec::integer("frames", 0)
          .range(0, std::nullopt)
          .describe("frames to produce; 0 = the preset's count"),
      ParamSpec::integer("first_frame", 0)
          .range(0, std::nullopt)
          .describe("index of the first frame: moving ground starts that far along"),
      ParamSpec::number("fps", 0.0)
          .range(0, 1000)
          .in_unit("1/s")
          .describe("pace of the frames; 0 = as fast as they are made"),
      ReplayHostTime::param(
          "the simulated capture time: the first frame's host time plus the device "
          "clock since (1/30 s a frame), so that stages that keep time (estimation.temporal) "
          "see the cameras' pace however slowly the frames render"),
      ParamSpec::number("ground_distance_mm", 0.0)
          .range(0, 5000)
          .in_unit("mm")
          .describe("mounting surface to soil; 0 = the preset's"),
      ParamSpec::number("noise_mm", 1.0)
          .range(0, 50)
          .in_unit("mm")
          .describe("ToF range noise (std) at 500 mm; grows with range squared"),
      ParamSpec::number("dropout", 0.002).range(0, 1).describe("fraction of pixels with no data"),
      ParamSpec::number("color_noise", 2.0)
          .range(0, 50)
          .in_unit("DN")
          .describe("colour sensor noise (std)"),
      ParamSpec::choice("color_format",
                        {"bgr8", "bayer_rggb8", "bayer_bggr8", "bayer_grbg8", "bayer_gbrg8"},
                        "bgr8")
          .describe("colour frame pixel format"),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<SceneSource>();
  return d;
}

}  // namespace

TILTH_STAGE(describe());

}  // namespace tilth::synthetic
