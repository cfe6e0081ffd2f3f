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
//   "segment": {"type": "segmentation.fusion", "params": {"index": "exg", "height_mm": 3}}
#include <opencv2/core.hpp>

#include "one_material_notice.h"
#include "residue_index.h"
#include "residue_output.h"
#include "soil_surface/soil_surface.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

class Fusion final : public Transform {
 public:
  explicit Fusion(const StageContext& context)
      : index_(parse_color_index(context.params.string("index")),
               static_cast<int>(context.params.integer("smoothing_px")),
               static_cast<int>(context.params.integer("max_smoothing_px"))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        surface_(context.params.number("height_mm"), context.params.number("max_height_mm"),
                 context.params.number("surface_px"), context.params.number("envelope_px")),
        output_(context.params),
        notice_(context.log) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat by_color, soil_color, height, by_height, unknown;
    const IndexSplit split = index_.classify(in.bgr, in.untrusted, by_color);
    notice_.report(frame.info().frame_id, !split.two_classes, split.text());
    cv::subtract(by_color, in.untrusted, by_color);
    cv::bitwise_or(by_color, in.unknown, soil_color);
    cv::bitwise_not(soil_color, soil_color);

    const double residue_mm = surface_.heights(in.depth_mm, in.missing, soil_color, height);
    cv::compare(height, residue_mm, by_height, cv::CMP_GT);  // NaN: no
    cv::bitwise_or(by_color, by_height, by_color);
    cv::compare(height, height, unknown, cv::CMP_NE);  // NaN: no surface, no height cue
    cv::bitwise_or(unknown, in.unknown, unknown);
    output_.emit(frame, in.area, by_color, cv::Mat(), unknown, in.depth_mm);
  }

 private:
  const ResidueIndex index_;
  const int min_value_;
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
      color_index_param(),   smoothing_px_param(), max_smoothing_px_param(), height_mm_param(),
      max_height_mm_param(), surface_px_param(),   envelope_px_param(),      dilation_px_param(),
      segmented_roi_param(), speckle_px_param(1),  min_value_param(),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<Fusion>();
  return d;
}

TILTH_STAGE(describe_fusion());

}  // namespace tilth::segmentation
