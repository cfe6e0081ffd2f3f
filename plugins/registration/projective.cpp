// registration.projective: for each depth pixel (u, v) with depth z (mm from the
// mounting surface) the ToF-frame point P_d = (z + z_offset_mm) * (x', y', 1), (x', y')
// its undistorted normalised coordinates, is moved into the colour camera,
// P_c = R * P_d + T, projected with the colour camera's intrinsics and distortion, and
// the colour there is copied to (u, v). No linearisation (the paper's eqs. 4-5), so a
// rotated rig and lens distortion are handled; see docs/registration.md.
//
//   depth (DepthImage) ──┐
//                        ├─► registration.projective ─► color (RegisteredColor)
//   color (ColorImage) ──┘
//
// Invariant: a pixel gets a colour only when its status is kValid; every other pixel is
// black and says why: kNoDepth (NaN depth), kOutsideColor (behind the colour camera or
// outside its image), kOccluded (the colour camera sees a nearer point there).
//
// Occlusion is a z-buffer over the colour image, in cells just large enough that a
// surface seen by both cameras leaves none empty (OcclusionCells): a first pass keeps the
// nearest point of each cell, and in the second a point more than occlusion_tolerance_mm
// behind it is occluded. The depth pixels are projected once, in the first pass.
//
//   {"type": "registration.projective",
//    "params": {"calibration": "rig.calib.json", "occlusion_tolerance_mm": 10,
//               "interpolation": "nearest"}}
#include "projective.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include "color_sampler.h"
#include "depth_to_color.h"
#include "tilth/error.h"
#include "tilth/message_pool.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/plugin.h"

namespace tilth::registration {
namespace {

constexpr int kLanes = 4;                                        // cv::v_float32x4
constexpr std::int64_t kMaxColorPixels = std::int64_t{1} << 24;  // float's exact integers
constexpr int kMaxColorSide = 1 << 16;

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height) + " px";
}

// The z-buffer's cells: squares of the colour image just large enough that the depth
// pixels of a surface seen by both cameras leave none empty. A depth pixel spans about
// d = fx_c / fx_d colour pixels, and the samples of a surface form a lattice of spacing d
// at any rotation, which leaves points up to d / sqrt(2) from the nearest sample: a cell
// of side sqrt(2) d always holds one. A point's cell is that of its nearest colour pixel.
struct OcclusionCells {
  explicit OcclusionCells(const RigCalibration& rig)
      : size(static_cast<int>(std::ceil(
            std::sqrt(2.0) * std::max(rig.color.fx / rig.depth.fx, rig.color.fy / rig.depth.fy)))),
        columns((rig.color.width + size - 1) / size),
        rows((rig.color.height + size - 1) / size) {}

  DepthToColor::CellGrid grid() const { return {size, columns}; }

  int size;
  int columns;
  int rows;
};

// What a frame in flight needs besides its output: the z-buffer, each depth pixel's
// colour pixel and cell (located in the first pass, read in the second), one row of depths
// along the colour axis (recomputed in the second pass: cheaper than keeping a frame of
// them), and the colour image as bgr8 when it comes as a Bayer mosaic.
struct Scratch {
  cv::Mat nearest_mm;  // CV_32FC1 per cell: the nearest depth along the colour axis
  std::vector<std::int32_t> color_pixel, cell;  // rows of DepthToColor::row_capacity()
  std::vector<float> color_depth;               // one row
  std::vector<float> color_u, color_v;          // one row, for bilinear sampling
  cv::Mat demosaiced;                           // CV_8UC3, from a Bayer mosaic
  cv::Mat continuous;  // the colour image, when it came with gaps between rows

  void prepare(const DepthToColor& map, const OcclusionCells& cells) {
    const auto row = static_cast<std::size_t>(map.row_capacity());
    for (auto* values : {&color_pixel, &cell}) values->resize(row * map.depth_height());
    for (auto* values : {&color_depth, &color_u, &color_v}) values->resize(row);
    reuse_or_create(nearest_mm, cells.rows, cells.columns, CV_32FC1);
    // Not Mat::setTo, which allocates a scratch buffer every call.
    std::fill_n(nearest_mm.ptr<float>(), nearest_mm.total(),
                std::numeric_limits<float>::infinity());
  }
};

struct Bgr {
  int b, g, r;
};

Bgr channels(std::uint32_t bgr24) {
  return {static_cast<int>(bgr24 & 0xFF), static_cast<int>((bgr24 >> 8) & 0xFF),
          static_cast<int>(bgr24 >> 16)};
}

// The four colour pixels around (u, v), blended; weights in 1/256.
template <class Sampler>
std::uint32_t bilinear(const Sampler& sampler, float u, float v, int height) {
  const int width = sampler.width();
  // u, v >= -0.5: truncation of u + 1 is floor(u) + 1.
  const int x0 = static_cast<int>(u + 1.0f) - 1;
  const int y0 = static_cast<int>(v + 1.0f) - 1;
  const int wx = static_cast<int>((u - static_cast<float>(x0)) * 256.0f + 0.5f);
  const int wy = static_cast<int>((v - static_cast<float>(y0)) * 256.0f + 0.5f);
  // The neighbours, clamped to the image.
  const int top_left = std::max(y0, 0) * width + std::max(x0, 0);
  const int right = x0 >= 0 && x0 + 1 < width ? 1 : 0;
  const int down = y0 >= 0 && y0 + 1 < height ? width : 0;
  const Bgr a = channels(sampler.at(top_left));
  const Bgr b = channels(sampler.at(top_left + right));
  const Bgr c = channels(sampler.at(top_left + down));
  const Bgr d = channels(sampler.at(top_left + down + right));
  const auto blend = [&](int ca, int cb, int cc, int cd) {
    const int upper = ca * (256 - wx) + cb * wx;
    const int lower = cc * (256 - wx) + cd * wx;
    return static_cast<std::uint32_t>((upper * (256 - wy) + lower * wy + (1 << 15)) >> 16);
  };
  return blend(a.b, b.b, c.b, d.b) | (blend(a.g, b.g, c.g, d.g) << 8) |
         (blend(a.r, b.r, c.r, d.r) << 16);
}

template <bool kBilinear, class Sampler>
void register_frame(const DepthToColor& map, const OcclusionCells& cells, const cv::Mat& depth,
                    const Sampler& sampler, const float occlusion_tolerance_mm, Scratch& scratch,
                    RegisteredColor& out) {
  scratch.prepare(map, cells);
  // Everything read per pixel is held in locals: the loops write bytes, and through a
  // byte pointer the compiler must assume any memory changed.
  const Sampler colors = sampler;
  float* const nearest_mm = scratch.nearest_mm.ptr<float>();
  float* const color_depth = scratch.color_depth.data();
  float* const color_u = scratch.color_u.data();
  float* const color_v = scratch.color_v.data();
  const int width = map.depth_width();
  const int height = map.depth_height();
  const int color_height = map.color_height();
  const auto row_start = [&](int v) { return static_cast<std::size_t>(v) * map.row_capacity(); };

  for (int v = 0; v < height; ++v) {  // the nearest point of each cell
    std::int32_t* const pixel = scratch.color_pixel.data() + row_start(v);
    std::int32_t* const cell = scratch.cell.data() + row_start(v);
    map.locate_row(v, depth.ptr<float>(v), cells.grid(), pixel, cell, color_depth);
    // Even pixels, then odd ones: neighbours often share a cell, and each update would
    // wait for the one before it to reach memory.
    for (int first = 0; first < 2; ++first) {
      for (int u = first; u < width; u += 2) {
        if (cell[u] >= 0) nearest_mm[cell[u]] = std::min(nearest_mm[cell[u]], color_depth[u]);
      }
    }
  }

  for (int v = 0; v < height; ++v) {
    const std::int32_t* const pixel = scratch.color_pixel.data() + row_start(v);
    const std::int32_t* const cell = scratch.cell.data() + row_start(v);
    const auto* z = depth.ptr<float>(v);
    if constexpr (kBilinear) {
      map.project_row(v, z, color_u, color_v, color_depth);
    } else {
      map.color_depth_row(v, z, color_depth);
    }
    auto* status = out.status.ptr<std::uint8_t>(v);
    auto* bgr = out.bgr.ptr<std::uint8_t>(v);
    const auto color_at = [&](int u) -> std::uint32_t {
      if (cell[u] < 0) {
        status[u] = std::isnan(z[u]) ? RegisteredColor::kNoDepth : RegisteredColor::kOutsideColor;
        return 0;
      }
      if (color_depth[u] > nearest_mm[cell[u]] + occlusion_tolerance_mm) {
        status[u] = RegisteredColor::kOccluded;
        return 0;
      }
      status[u] = RegisteredColor::kValid;
      return kBilinear ? bilinear(colors, color_u[u], color_v[u], color_height)
                       : colors.at(pixel[u]);
    };
    // Four bytes a pixel, the fourth the next pixel's blue, which its own turn overwrites;
    // three for the row's last pixel.
    for (int u = 0; u + 1 < width; ++u) {
      const std::uint32_t color = color_at(u);
      std::memcpy(bgr + 3 * u, &color, 4);
    }
    const Bgr last = channels(color_at(width - 1));
    bgr[3 * width - 3] = static_cast<std::uint8_t>(last.b);
    bgr[3 * width - 2] = static_cast<std::uint8_t>(last.g);
    bgr[3 * width - 1] = static_cast<std::uint8_t>(last.r);
  }
}

class ProjectiveRegistration final : public Transform {
 public:
  explicit ProjectiveRegistration(const StageContext& context)
      : ProjectiveRegistration(context, context.params.path("calibration").string()) {}

  void process(Frame& frame) override {
    const cv::Mat& depth = frame.input<DepthImage>(0).mm;
    const ColorImage& color = frame.input<ColorImage>(1);
    check(depth, color);

    auto out = outputs_.acquire();
    reuse_or_create(out->bgr, map_.depth_height(), map_.depth_width(), CV_8UC3);
    reuse_or_create(out->status, map_.depth_height(), map_.depth_width(), CV_8UC1);
    const auto scratch = scratch_.acquire();
    // The samplers address pixels by index: a colour image with gaps between its rows
    // (a region of a larger one) is copied first.
    const cv::Mat* pixels = &color.pixels;
    if (!color.pixels.isContinuous()) {
      color.pixels.copyTo(scratch->continuous);
      pixels = &scratch->continuous;
    }
    const auto run = [&](const auto& sampler) {
      if (bilinear_) {
        register_frame<true>(map_, cells_, depth, sampler, occlusion_tolerance_mm_, *scratch, *out);
      } else {
        register_frame<false>(map_, cells_, depth, sampler, occlusion_tolerance_mm_, *scratch,
                              *out);
      }
    };
    // OpenCV's SIMD demosaicing of the whole image costs less than demosaicing only the
    // pixels read, one at a time.
    const auto run_demosaiced = [&](int code) {
      cv::cvtColor(*pixels, scratch->demosaiced, code);
      run(BgrSampler(scratch->demosaiced));
    };
    switch (color.format) {
      case PixelFormat::kBgr8:
        run(BgrSampler(*pixels));
        break;
      case PixelFormat::kRgb8:
        run(RgbSampler(*pixels));
        break;
      case PixelFormat::kMono8:
        run(MonoSampler(*pixels));
        break;
      // OpenCV names a mosaic by its second row's second and third pixels, one pixel
      // off the usual naming by the top-left 2x2 tile.
      case PixelFormat::kBayerRggb8:
        run_demosaiced(cv::COLOR_BayerBG2BGR);
        break;
      case PixelFormat::kBayerBggr8:
        run_demosaiced(cv::COLOR_BayerRG2BGR);
        break;
      case PixelFormat::kBayerGrbg8:
        run_demosaiced(cv::COLOR_BayerGB2BGR);
        break;
      case PixelFormat::kBayerGbrg8:
        run_demosaiced(cv::COLOR_BayerGR2BGR);
        break;
    }
    frame.set_output(0, std::move(out));
  }

 private:
  ProjectiveRegistration(const StageContext& context, std::string file)
      : ProjectiveRegistration(context, file, load_calibration(file)) {}
  ProjectiveRegistration(const StageContext& context, const std::string& file,
                         const RigCalibration& rig)
      : file_(file),
        map_(rig, file),
        cells_(rig),
        occlusion_tolerance_mm_(
            static_cast<float>(context.params.number("occlusion_tolerance_mm"))),
        bilinear_(context.params.string("interpolation") == "bilinear") {
    // Colour pixel indices are computed in float (DepthToColor::locate_row).
    if (static_cast<std::int64_t>(rig.color.width) * rig.color.height >= kMaxColorPixels ||
        rig.color.width >= kMaxColorSide || rig.color.height >= kMaxColorSide) {
      throw Error(file + ":/color_camera: a colour image of " +
                  size_text(rig.color.width, rig.color.height) +
                  " is larger than registration.projective supports (2^24 px, sides below "
                  "65536)");
    }
  }

  void check(const cv::Mat& depth, const ColorImage& color) const {
    if (depth.type() != CV_32FC1) {
      throw Error("depth image has pixel type " + cv::typeToString(depth.type()) +
                  "; expected CV_32FC1 (mm)");
    }
    if (depth.cols != map_.depth_width() || depth.rows != map_.depth_height()) {
      throw Error("depth image is " + size_text(depth.cols, depth.rows) + " but the calibration " +
                  file_ + " is for " + size_text(map_.depth_width(), map_.depth_height()));
    }
    const int expected_type = CV_8UC(channels(color.format));
    if (color.pixels.type() != expected_type) {
      throw Error("colour image (" + std::string(to_string(color.format)) + ") has pixel type " +
                  cv::typeToString(color.pixels.type()) + "; expected " +
                  cv::typeToString(expected_type));
    }
    if (color.pixels.cols != map_.color_width() || color.pixels.rows != map_.color_height()) {
      throw Error("colour image is " + size_text(color.pixels.cols, color.pixels.rows) +
                  " but the calibration " + file_ + " is for " +
                  size_text(map_.color_width(), map_.color_height()));
    }
  }

  const std::string file_;
  const DepthToColor map_;
  const OcclusionCells cells_;
  const float occlusion_tolerance_mm_;
  const bool bilinear_;
  MessagePool<RegisteredColor> outputs_;
  MessagePool<Scratch> scratch_;  // one per frame in flight
};

}  // namespace

StageDescriptor describe_projective() {
  StageDescriptor d;
  d.type = "registration.projective";
  d.summary =
      "colour resampled onto the depth grid (full projective mapping, lens distortion, "
      "occlusion)";
  d.inputs = {
      PortSpec::of<DepthImage>("depth", "mm from the mounting surface; NaN = no depth"),
      PortSpec::of<ColorImage>("color", "bgr8, rgb8, mono8 or 8-bit Bayer"),
  };
  d.outputs = {PortSpec::of<RegisteredColor>("color", "bgr on the depth grid, status per pixel")};
  d.params = {
      ParamSpec::path("calibration", std::nullopt).describe("rig calibration file"),
      ParamSpec::number("occlusion_tolerance_mm", 10.0)
          .range(0, std::nullopt)
          .in_unit("mm")
          .describe("a point this much farther than the nearest one seen at the same colour "
                    "pixels is occluded"),
      ParamSpec::choice("interpolation", {"nearest", "bilinear"}, "nearest")
          .describe("colour sampling: nearest keeps measured colours, bilinear blends four"),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<ProjectiveRegistration>();
  return d;
}

TILTH_STAGE(describe_projective());

}  // namespace tilth::registration
