// segmentation.fusion: colour and height together, for residue whose colour is close to
// the soil's (wet, dark, weathered straw; shadows) and soil the colour alone cannot vouch
// for.
//
//   color ──► colour index, Otsu (as segmentation.color_index) ──► colour says residue ─┐
//     └──► colour says soil ──► supports the soil surface                             ├─► OR ─►
//   depth ──► height above the surface (as segmentation.depth_aided) > height_mm ─────┘ despeckle,
//                                                                                    dilate ─► mask
//
// Invariant: one cue is enough for residue, both are needed for soil. A residue pixel
// taken for soil biases the distance by the residue's height; a soil pixel taken for
// residue only costs visible soil. So a pixel is soil only when its colour is trusted and
// on the soil side, it has depth, and it lies no more than height_mm above the surface;
// it is unknown when either cue is missing (untrusted colour, no depth, or no soil surface
// near it), and residue when either cue says so.
//
// Where the depth puts a pixel on the soil, a colour only a little off the soil's own is
// not enough for residue: at the soil's level (no higher than the residue height above
// both the surface and the plane through the farthest depths), colour's residue must lie
// soil_color_sigmas robust standard deviations beyond the median colour of the pixels at
// that level. Sun-bleached straw differs from soil by about as much as the soil's colour
// varies; Otsu's threshold then falls among the soil's colours, and under heavy cover a
// third of the soil was taken for residue and every frame was lost (bleached_cover in
// docs/accuracy.md). The plane keeps the lowest straws of a pile residue, which the
// envelope puts at the soil's level (covered_wet).
//
//   "segment": {"type": "segmentation.fusion", "params": {"index": "exg", "height_mm": 3}}
#include <cstdint>
#include <optional>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "one_material_notice.h"
#include "residue_index.h"
#include "residue_output.h"
#include "soil_surface/soil_surface.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

// Marks in `level` the pixels the depth puts on the soil: no higher than `residue_mm`
// above both the surface and the farthest plane, with a trusted colour, and more than
// kApartFromResiduePx from residue by height. Nearer, a pixel's colour takes some of the
// residue's (the index's box, the registration's sampling) and multipath lengthens its
// depth: with them, the distance on the field scenes at 8 DN of colour noise read 0.1 mm
// farther.
constexpr int kApartFromResiduePx = 2;
void at_soil_level(const cv::Mat& height, const cv::Mat& plane_height, double residue_mm,
                   const cv::Mat& untrusted, const cv::Mat& by_height, cv::Mat& level) {
  thread_local cv::Mat under_plane, near_residue;
  constexpr int kSide = 2 * kApartFromResiduePx + 1;
  static const cv::Mat kNear = cv::Mat::ones(kSide, kSide, CV_8UC1);
  cv::compare(height, residue_mm, level, cv::CMP_LE);  // NaN: no
  cv::compare(plane_height, residue_mm, under_plane, cv::CMP_LE);
  cv::bitwise_and(level, under_plane, level);
  cv::subtract(level, untrusted, level);
  cv::dilate(by_height, near_residue, kNear);
  cv::subtract(level, near_residue, level);
}

// Clears `by_color` where a pixel is at the soil's level (marked in `level`) and its index
// lies within `sigmas` robust standard deviations of the median of the pixels there, on
// residue's side.
void soil_colored_at_soil_level(const ResidueIndex& colors, const IndexSplit& split,
                                const cv::Mat& index, const cv::Mat& level, double sigmas,
                                cv::Mat& by_color) {
  const std::optional<IndexSpread> soil = colors.spread(index, level);
  if (!soil) return;
  const double beyond = sigmas * soil->sigma;
  thread_local cv::Mat soil_colored;
  // NaN compares false: no colour, left as it is.
  if (split.residue_above) {
    cv::compare(index, soil->median + beyond, soil_colored, cv::CMP_LT);
  } else {
    cv::compare(index, soil->median - beyond, soil_colored, cv::CMP_GT);
  }
  cv::bitwise_and(soil_colored, level, soil_colored);
  cv::subtract(by_color, soil_colored, by_color);
}

class Fusion final : public Transform {
 public:
  explicit Fusion(const StageContext& context)
      : index_(parse_color_index(context.params.string("index")),
               static_cast<int>(context.params.integer("smoothing_px")),
               static_cast<int>(context.params.integer("max_smoothing_px"))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        soil_color_sigmas_(context.params.number("soil_color_sigmas")),
        surface_(context.params.number("height_mm"), context.params.number("max_height_mm"),
                 context.params.number("surface_px"), context.params.number("envelope_px")),
        output_(context.params),
        notice_(context.log) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat by_color, soil_color, index, height, plane_height, by_height, level,
        unknown;
    const IndexSplit split = index_.classify(in.bgr, in.untrusted, by_color, index);
    notice_.report(frame.info().frame_id, !split.two_classes, split.text());
    cv::subtract(by_color, in.untrusted, by_color);
    cv::bitwise_or(by_color, in.unknown, soil_color);
    cv::bitwise_not(soil_color, soil_color);

    const double residue_mm =
        soil_color_sigmas_ > 0
            ? surface_.heights(in.depth_mm, in.missing, soil_color, height, plane_height)
            : surface_.heights(in.depth_mm, in.missing, soil_color, height);
    cv::compare(height, residue_mm, by_height, cv::CMP_GT);  // NaN: no
    if (soil_color_sigmas_ > 0) {
      at_soil_level(height, plane_height, residue_mm, in.untrusted, by_height, level);
      soil_colored_at_soil_level(index_, split, index, level, soil_color_sigmas_, by_color);
    }
    cv::bitwise_or(by_color, by_height, by_color);
    cv::compare(height, height, unknown, cv::CMP_NE);  // NaN: no surface, no height cue
    cv::bitwise_or(unknown, in.unknown, unknown);
    output_.emit(frame, in.area, by_color, cv::Mat(), unknown, in.depth_mm);
  }

 private:
  const ResidueIndex index_;
  const int min_value_;
  const double soil_color_sigmas_;
  const SoilSurface surface_;
  ResidueOutput output_;
  OneMaterialNotice notice_;
};

}  // namespace

StageDescriptor describe_fusion() {
  StageDescriptor d;
  d.type = "segmentation.fusion";
  d.summary = "residue mask from colour OR height above the soil surface; soil needs both";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      color_index_param(),
      smoothing_px_param(),
      max_smoothing_px_param(),
      height_mm_param(),
      max_height_mm_param(),
      surface_px_param(),
      envelope_px_param(),
      dilation_px_param(),
      segmented_roi_param(),
      speckle_px_param(1),
      min_value_param(),
      ParamSpec::number("soil_color_sigmas", 1.5)
          .range(0, 10)
          .describe("at the soil's level by depth, colour is residue only this many robust "
                    "standard deviations beyond the median colour there (bleached straw); "
                    "0: Otsu's threshold alone"),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<Fusion>();
  return d;
}

TILTH_STAGE(describe_fusion());

}  // namespace tilth::segmentation
