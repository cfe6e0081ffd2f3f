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
// outside its image), kOccluded (the colour camera sees a nearer point there),
// kNotRegistered (it is outside the region of interest and the 8 px around it that the
// segmentation reads, its columns rounded out to whole vectors). The z-buffer always holds
// every depth pixel, so occlusion inside the region is the same as in a whole image.
//
// A colour image that is a window of the calibrated image (its camera reads out a region
// of interest: ColorImage::sensor_offset) is registered with the calibration of that
// window (with_color_window); depth pixels whose colour lies outside it are kOutsideColor.
//
// Occlusion is a z-buffer over the colour image, in cells just large enough that a
// surface seen by both cameras leaves none empty (OcclusionCells): a first pass keeps the
// nearest point of each cell, and in the second a point more than occlusion_tolerance_mm
// behind it is occluded, or more than kNoiseSigmas times the frame's depth noise when
// that is more: the nearest of a cell's noisy points is nearer than the surface, and a
// fixed tolerance would take for occluded the points whose noise put them farthest, and
// so read the soil nearer than it is. Each pass projects the depth pixels row by row (see
// Scratch).
//
//   {"type": "registration.projective",
//    "params": {"occlusion_tolerance_mm": 10,
//               "interpolation": "nearest"}}
#include "projective.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "color/color_conversion.h"
#include "color_sampler.h"
#include "depth_noise/depth_noise.h"
#include "depth_to_color.h"
#include "roi/region_of_interest.h"
#include "row_kernels.h"
#include "tilth/error.h"
#include "tilth/frame_calibration.h"
#include "tilth/message_pool.h"
#include "tilth/messages/color_image.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/plugin.h"

namespace tilth::registration {
namespace {

std::string size_text(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height) + " px";
}

// The z-buffer's cells: squares of the colour image just large enough that the depth
// pixels of a surface seen by both cameras leave none empty. A depth pixel spans about
// d = fx_c / fx_d colour pixels, and the samples of a surface form a lattice of spacing d
// at any rotation, which leaves points up to d / sqrt(2) from the nearest sample: a cell
// of side sqrt(2) d always holds one.
struct OcclusionCells {
  explicit OcclusionCells(const RigCalibration& rig)
      : size(static_cast<int>(std::ceil(
            std::sqrt(2.0) * std::max(rig.color.fx / rig.depth.fx, rig.color.fy / rig.depth.fy)))),
        columns((rig.color.width + size - 1) / size),
        rows((rig.color.height + size - 1) / size) {}

  int size;
  int columns;
  int rows;

  CellGrid grid() const { return {size, columns, columns * rows}; }
};

// One row of depth pixels as the colour camera sees them, in plain arrays: the
// registration writes bytes, and through a byte pointer the compiler must assume any
// memory changed, so everything read per pixel is held in locals, not reached through
// objects.
struct LocatedRow {
  const float* u;  // colour pixel
  const float* v;
  const float* depth_mm;  // along the colour axis; NaN: not in the colour image
  const int* key;         // of the sampler's pixels (Addressing)
  const int* cell;        // CellGrid::outside: not in the colour image
};

// The part of the depth grid registered: rows [first_row, last_row), and in them columns
// [first_column, last_column), from and to whole vectors of kRowLanes (or the row's end),
// so that the kernels read the located rows as they would whole.
struct Registered {
  int first_row;
  int last_row;
  int first_column;
  int last_column;

  static Registered around(const cv::Rect& region, int depth_width) {
    return {
        region.y, region.y + region.height, region.x / kRowLanes * kRowLanes,
        std::min(depth_width, (region.x + region.width + kRowLanes - 1) / kRowLanes * kRowLanes)};
  }
  int columns() const { return last_column - first_column; }
};

// What a frame in flight needs besides its output: the z-buffer, the depth pixels as the
// colour camera sees them, and the demosaiced colour image for bilinear sampling of a
// mosaic. The first pass keeps the registered rows' locations for the second (12 bytes a
// pixel, 2 MB a frame for the chain's region: with 8 or 4 lanes, projecting and locating
// the rows anew costs more), and locates every other row into one spare row, which stays
// in the nearest cache; kept rows include their colour pixels for bilinear sampling only,
// which reads them in the second pass.
struct Scratch {
  // An empty cell's depth: the float whose bytes are all kFarByte, 3.4e38 mm, farther
  // than any point.
  static constexpr int kFarByte = 0x7f;

  std::vector<float> nearest_mm;  // per cell: the nearest depth along the colour axis
  std::vector<float> color_u, color_v, color_depth;
  std::vector<int> key, cell;
  cv::Mat demosaiced;  // CV_8UC3

  void prepare(const DepthToColor& map, const OcclusionCells& cells, const Registered& registered,
               bool bilinear) {
    first_kept_ = registered.first_row;
    kept_ = registered.last_row - registered.first_row;
    const auto row = static_cast<std::size_t>(map.row_capacity());
    const auto frame = row * static_cast<std::size_t>(kept_ + 1);
    for (auto* values : {&color_u, &color_v}) values->resize(bilinear ? frame : row);
    color_depth.resize(frame);
    for (auto* values : {&key, &cell}) values->resize(frame);
    // Cleared to kFar with memset, the fastest way to clear it.
    nearest_mm.resize(static_cast<std::size_t>(cells.grid().count()));
    std::memset(nearest_mm.data(), kFarByte, nearest_mm.size() * sizeof(float));
  }

  // The first pass: projects depth row `v` and finds each point's cell and the pixels for
  // the sampler, kept for the second pass.
  LocatedRow locate_first(const DepthToColor& map, const OcclusionCells& cells,
                          const cv::Mat& depth, int v, const Addressing& addressing) {
    const Slots row = slots(map, v);
    map.project_row(v, depth.ptr<float>(v), row.u, row.v, row.depth_mm);
    map.kernels().locate(addressing, cells.grid(), map.color_width(), map.color_height(),
                         map.row_capacity(), row.u, row.v, row.depth_mm, row.key, row.cell);
    return row.located();
  }

  // The second pass: row `v` as the first kept it.
  LocatedRow locate_second(const DepthToColor& map, int v) { return slots(map, v).located(); }

 private:
  struct Slots {
    float *u, *v, *depth_mm;
    int *key, *cell;

    LocatedRow located() const { return {u, v, depth_mm, key, cell}; }
  };

  // Row v's slot: its own for a kept row, else the spare one after them.
  Slots slots(const DepthToColor& map, int v) {
    const auto capacity = static_cast<std::size_t>(map.row_capacity());
    const int slot = v >= first_kept_ && v < first_kept_ + kept_ ? v - first_kept_ : kept_;
    const std::size_t start = static_cast<std::size_t>(slot) * capacity;
    const std::size_t uv = color_u.size() > start ? start : 0;
    return {color_u.data() + uv, color_v.data() + uv, color_depth.data() + start,
            key.data() + start, cell.data() + start};
  }

  int first_kept_ = 0;
  int kept_ = 0;
};

// The first pass: the nearest point of each cell.
void fill_z_buffer(const DepthToColor& map, const OcclusionCells& cells, const cv::Mat& depth,
                   const Addressing& addressing, const Registered& registered, bool bilinear,
                   Scratch& scratch) {
  scratch.prepare(map, cells, registered, bilinear);
  for (int v = 0; v < map.depth_height(); ++v) {
    const LocatedRow row = scratch.locate_first(map, cells, depth, v, addressing);
    map.kernels().keep_nearest(cells.grid(), map.row_capacity(), row.depth_mm, row.cell,
                               scratch.nearest_mm.data());
  }
}

Visibility visibility(const Scratch& scratch, const OcclusionCells& cells, float tolerance_mm) {
  return {scratch.nearest_mm.data(), cells.grid().outside,      tolerance_mm,
          RegisteredColor::kValid,   RegisteredColor::kNoDepth, RegisteredColor::kOutsideColor,
          RegisteredColor::kOccluded};
}

void register_nearest(const DepthToColor& map, const OcclusionCells& cells, const cv::Mat& depth,
                      const NearestPixels& pixels, float occlusion_tolerance_mm,
                      Registered registered, Scratch& scratch, RegisteredColor& out) {
  fill_z_buffer(map, cells, depth, pixels.addressing, registered, false, scratch);
  const Visibility seen = visibility(scratch, cells, occlusion_tolerance_mm);
  const int u = registered.first_column;
  for (int v = registered.first_row; v < registered.last_row; ++v) {
    const LocatedRow row = scratch.locate_second(map, v);
    map.kernels().resolve(seen, pixels.word, registered.columns(), depth.ptr<float>(v) + u,
                          row.depth_mm + u, row.cell + u, row.key + u,
                          out.status.ptr<std::uint8_t>(v) + u,
                          out.bgr.ptr<std::uint8_t>(v) + 3 * u);
  }
}

// The four pixels around (u, v), blended; u, v >= -0.5.
template <class Sampler>
Bgr bilinear_sample(const Sampler& sampler, float u, float v, int width, int height) {
  // Truncation of u + 1 is floor(u) + 1. Weights in 1/256.
  const int x0 = static_cast<int>(u + 1.0f) - 1;
  const int y0 = static_cast<int>(v + 1.0f) - 1;
  const int wx = static_cast<int>((u - static_cast<float>(x0)) * 256.0f + 0.5f);
  const int wy = static_cast<int>((v - static_cast<float>(y0)) * 256.0f + 0.5f);
  // The neighbours, clamped to the image.
  const std::ptrdiff_t top_left = sampler.offset(std::max(x0, 0), std::max(y0, 0));
  const std::ptrdiff_t right = x0 >= 0 && x0 + 1 < width ? Sampler::kPixelBytes : 0;
  const std::ptrdiff_t down = y0 >= 0 && y0 + 1 < height ? sampler.step() : 0;
  const Bgr a = sampler.at(top_left);
  const Bgr b = sampler.at(top_left + right);
  const Bgr c = sampler.at(top_left + down);
  const Bgr d = sampler.at(top_left + down + right);
  const auto blend = [&](int ca, int cb, int cc, int cd) {
    const int upper = ca * (256 - wx) + cb * wx;
    const int lower = cc * (256 - wx) + cd * wx;
    return (upper * (256 - wy) + lower * wy + (1 << 15)) >> 16;
  };
  return {blend(a.b, b.b, c.b, d.b), blend(a.g, b.g, c.g, d.g), blend(a.r, b.r, c.r, d.r)};
}

template <class Sampler>
void register_bilinear(const DepthToColor& map, const OcclusionCells& cells, const cv::Mat& depth,
                       const Sampler& sampler, const float occlusion_tolerance_mm,
                       Registered registered, Scratch& scratch, RegisteredColor& out) {
  const Sampler colors = sampler;  // a local: see LocatedRow
  fill_z_buffer(map, cells, depth, colors.addressing(), registered, true, scratch);
  const float* const nearest_mm = scratch.nearest_mm.data();
  const int outside = cells.grid().outside;
  const int color_width = map.color_width();
  const int color_height = map.color_height();
  for (int v = registered.first_row; v < registered.last_row; ++v) {
    const LocatedRow row = scratch.locate_second(map, v);
    const auto* z = depth.ptr<float>(v);
    auto* status = out.status.ptr<std::uint8_t>(v);
    auto* bgr = out.bgr.ptr<std::uint8_t>(v);
    for (int u = registered.first_column; u < registered.last_column; ++u) {
      const int cell = row.cell[u];
      const bool visible = row.depth_mm[u] <= nearest_mm[cell] + occlusion_tolerance_mm;
      status[u] = visible            ? RegisteredColor::kValid
                  : cell != outside  ? RegisteredColor::kOccluded
                  : std::isnan(z[u]) ? RegisteredColor::kNoDepth
                                     : RegisteredColor::kOutsideColor;
      const Bgr color = visible
                            ? bilinear_sample(colors, row.u[u], row.v[u], color_width, color_height)
                            : Bgr{0, 0, 0};
      bgr[3 * u] = static_cast<std::uint8_t>(color.b);
      bgr[3 * u + 1] = static_cast<std::uint8_t>(color.g);
      bgr[3 * u + 2] = static_cast<std::uint8_t>(color.r);
    }
  }
}

// What registering a frame needs from its calibration.
struct Geometry {
  Geometry(const RigCalibration& rig, const RowKernels& kernels)
      : origin(rig.origin), map(rig, rig.origin, kernels), cells(rig) {}

  std::string origin;  // the calibration's, for messages
  DepthToColor map;
  OcclusionCells cells;
};

// The geometry for colour images that are a window of the calibrated image (a camera's
// region of interest): made from the calibration with that window, once per calibration
// and window.
struct WindowGeometry {
  std::shared_ptr<const RigCalibration> rig;  // the calibration it was made from
  cv::Rect window;
  std::shared_ptr<const Geometry> geometry;
  bool warned = false;  // that the window is too small for the region
};

// The pixels of `region` whose colour lies outside the colour image.
int outside_color(const RegisteredColor& out, const cv::Rect& region) {
  int count = 0;
  for (int v = region.y; v < region.y + region.height; ++v) {
    const std::uint8_t* status = out.status.ptr<std::uint8_t>(v) + region.x;
    count +=
        static_cast<int>(std::count(status, status + region.width, RegisteredColor::kOutsideColor));
  }
  return count;
}

class ProjectiveRegistration final : public Transform {
 public:
  // Two samples of one surface differ by more than 4 sigma (2.8 standard deviations of
  // their difference) in 0.5 % of pairs. The simulator's depth noise is 1.3-2.1 mm on soil
  // at 518-585 mm, which leaves the default 10 mm; at three times that, 4 sigma is 28 mm.
  static constexpr float kNoiseSigmas = 4.0f;

  explicit ProjectiveRegistration(const StageContext& context)
      : log_(context.log),
        kernels_(row_kernels(context.params.string("instruction_set"))),
        calibration_(
            context.params, context.log,
            [&kernels = kernels_](const RigCalibration& rig) { return Geometry(rig, kernels); }),
        occlusion_tolerance_mm_(
            static_cast<float>(context.params.number("occlusion_tolerance_mm"))),
        bilinear_(context.params.string("interpolation") == "bilinear"),
        roi_(context.params.json("roi"), RegionOfInterest::Whole::kImage) {}

  void process(Frame& frame) override {
    const DepthImage& depth = frame.input<DepthImage>(0);
    const ColorImage& color = frame.input<ColorImage>(1);
    const auto geometry_held = geometry_for(calibration_.for_frame(depth.rig), color);
    const Geometry& geometry = *geometry_held;
    check(geometry, depth.mm, color);

    const DepthToColor& map = geometry.map;
    auto out = outputs_.acquire();
    reuse_or_create(out->bgr, map.depth_height(), map.depth_width(), CV_8UC3);
    reuse_or_create(out->status, map.depth_height(), map.depth_width(), CV_8UC1);
    const cv::Rect area = roi_.around(depth.mm.size(), RegionOfInterest::kMarginPx);
    const Registered registered = Registered::around(area, map.depth_width());
    mark_not_registered(registered, *out);
    const float tolerance_mm =
        kNoiseSigmas * depth_noise_mm(depth.mm, area, occlusion_tolerance_mm_ / kNoiseSigmas);
    const auto scratch = scratch_.acquire();
    if (bilinear_) {
      register_bilinear(geometry, depth.mm, color, tolerance_mm, registered, *scratch, *out);
    } else {
      register_nearest(map, geometry.cells, depth.mm, nearest_pixels(color.pixels, color.format),
                       tolerance_mm, registered, *scratch, *out);
    }
    warn_if_window_too_small(*out, depth.mm.size(), geometry_held);
    frame.set_output(0, std::move(out));
  }

 private:
  using Used = FrameCalibration<Geometry>::Used;

  // Once per window: the region has pixels whose colour lies outside the window, as when
  // the ground comes nearer or goes farther than the window was chosen for.
  void warn_if_window_too_small(const RegisteredColor& out, cv::Size depth_size,
                                const std::shared_ptr<const Geometry>& geometry) {
    // Counted only while it may still be said: not for a whole image, nor once said.
    std::unique_lock lock(window_mutex_);
    if (window_.geometry != geometry || window_.warned) return;
    lock.unlock();
    const cv::Rect region = roi_.on(depth_size);
    const int outside = outside_color(out, region);
    if (outside == 0) return;
    lock.lock();
    if (window_.geometry != geometry || window_.warned) return;
    window_.warned = true;
    log_.warning(std::to_string(outside) + " of the region's " + std::to_string(region.area()) +
                 " px see colour outside the colour window " + window_text(window_.window) +
                 ": is the ground nearer or farther than the window was chosen for? Widen it "
                 "(tilth calibrate color-window); said once per window");
  }

  // The calibration's geometry, or its window's when the colour image is a window of the
  // calibrated image.
  std::shared_ptr<const Geometry> geometry_for(std::shared_ptr<const Used> used,
                                               const ColorImage& color) {
    const RigCalibration& rig = *used->rig;
    const cv::Rect window = color.sensor_window();
    if (!color.sensor_offset || window == cv::Rect(0, 0, rig.color.width, rig.color.height)) {
      return {used, &used->derived};
    }
    std::lock_guard lock(window_mutex_);
    if (window_.rig != used->rig || window_.window != window) {
      auto geometry = std::make_shared<const Geometry>(with_color_window(rig, window), kernels_);
      log_.info("colour images are a window of the sensor: registering with " + geometry->origin);
      window_ = {used->rig, window, std::move(geometry), false};
    }
    return window_.geometry;
  }

  // Bilinear sampling blends demosaiced pixels.
  void register_bilinear(const Geometry& geometry, const cv::Mat& depth, const ColorImage& color,
                         float tolerance_mm, Registered registered, Scratch& scratch,
                         RegisteredColor& out) const {
    const auto run = [&](const auto& sampler) {
      registration::register_bilinear(geometry.map, geometry.cells, depth, sampler, tolerance_mm,
                                      registered, scratch, out);
    };
    switch (color.format) {
      case PixelFormat::kBgr8:
        return run(BgrSampler(color.pixels));
      case PixelFormat::kRgb8:
        return run(RgbSampler(color.pixels));
      case PixelFormat::kMono8:
        return run(MonoSampler(color.pixels));
      case PixelFormat::kBayerRggb8:
      case PixelFormat::kBayerBggr8:
      case PixelFormat::kBayerGrbg8:
      case PixelFormat::kBayerGbrg8:
        color::to_bgr(color.pixels, color.format, scratch.demosaiced);
        return run(BgrSampler(scratch.demosaiced));
    }
  }

  // Every pixel outside `registered`; the images are continuous (reuse_or_create), so a
  // run of pixels may go on from one row's end into the next row's start.
  static void mark_not_registered(const Registered& registered, RegisteredColor& out) {
    const auto mark = [&out](int row, int column, int count) {
      if (count <= 0) return;
      std::memset(out.status.ptr(row) + column, RegisteredColor::kNotRegistered,
                  static_cast<std::size_t>(count));
      std::memset(out.bgr.ptr(row) + 3 * column, 0, 3 * static_cast<std::size_t>(count));
    };
    const int width = out.status.cols;
    const int first = registered.first_row, last = registered.last_row;  // first < last
    // Before the first registered pixel, between a row's last and the next row's first,
    // and after the last.
    mark(0, 0, first * width + registered.first_column);
    for (int row = first; row < last; ++row) {
      const int to_next =
          row + 1 < last ? registered.first_column : (out.status.rows - row - 1) * width;
      mark(row, registered.last_column, width - registered.last_column + to_next);
    }
  }

  static void check(const Geometry& geometry, const cv::Mat& depth, const ColorImage& color) {
    const DepthToColor& map = geometry.map;
    if (depth.type() != CV_32FC1) {
      throw Error("depth image has pixel type " + cv::typeToString(depth.type()) +
                  "; expected CV_32FC1 (mm)");
    }
    if (depth.cols != map.depth_width() || depth.rows != map.depth_height()) {
      throw Error("depth image is " + size_text(depth.cols, depth.rows) + " but the calibration " +
                  geometry.origin + " is for " + size_text(map.depth_width(), map.depth_height()));
    }
    const int expected_type = CV_8UC(channels(color.format));
    if (color.pixels.type() != expected_type) {
      throw Error("colour image (" + std::string(to_string(color.format)) + ") has pixel type " +
                  cv::typeToString(color.pixels.type()) + "; expected " +
                  cv::typeToString(expected_type));
    }
    if (color.pixels.cols != map.color_width() || color.pixels.rows != map.color_height()) {
      throw Error("colour image is " + size_text(color.pixels.cols, color.pixels.rows) +
                  " but the calibration " + geometry.origin + " is for " +
                  size_text(map.color_width(), map.color_height()));
    }
  }

  const Logger log_;
  const RowKernels& kernels_;
  FrameCalibration<Geometry> calibration_;
  std::mutex window_mutex_;
  WindowGeometry window_;
  const float occlusion_tolerance_mm_;
  const bool bilinear_;
  const RegionOfInterest roi_;
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
      frame_calibration_param(),
      ParamSpec::number("occlusion_tolerance_mm", 10.0)
          .range(0, std::nullopt)
          .in_unit("mm")
          .describe("a point this much farther than the nearest one seen at the same colour "
                    "pixels is occluded; on noisier depth 4 times the frame's depth noise"),
      ParamSpec::choice("interpolation", {"nearest", "bilinear"}, "nearest")
          .describe("colour sampling: nearest keeps measured colours (of a Bayer mosaic: the "
                    "2x2 quad nearest the point), bilinear blends four demosaiced pixels"),
      roi_param(RegionOfInterest::Whole::kImage),
      ParamSpec::choice("instruction_set", row_kernel_levels(), "auto")
          .describe("the vector loops' instruction set: auto = the widest this CPU runs; "
                    "others for comparison"),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<ProjectiveRegistration>();
  return d;
}

TILTH_STAGE(describe_projective());

}  // namespace tilth::registration
