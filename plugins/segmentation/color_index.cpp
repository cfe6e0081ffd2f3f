// segmentation.color_index: residue from a colour index with an automatic threshold.
//
//   color ──► mean over a (2r+1)^2 box ──► index (exg | exr | exgr | hue) ──► Otsu's
//   threshold over the trusted pixels ──► two materials? ──► residue ──► despeckle ──►
//   dilate ──► mask, soil_depth                       └── no ──► absolute boundary
//
// Invariant: no threshold is set by hand. Otsu's always splits a histogram, even of one
// material; when the means of its two classes lie closer than the index's minimum gap,
// the frame shows one material and the index's absolute boundary decides each pixel, so
// a frame of bare soil stays soil and a frame covered by straw stays residue.
//
//   "segment": {"type": "segmentation.color_index", "params": {"index": "exg"}}
#include <opencv2/core.hpp>

#include "one_material_notice.h"
#include "residue_index.h"
#include "residue_output.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

class ColorIndexStage final : public Transform {
 public:
  explicit ColorIndexStage(const StageContext& context)
      : index_(parse_color_index(context.params.string("index")),
               static_cast<int>(context.params.integer("smoothing_px")),
               static_cast<int>(context.params.integer("max_smoothing_px"))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        output_(context.params),
        notice_(context.log) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat residue;
    const IndexSplit split = index_.classify(in.bgr, in.untrusted, residue);
    notice_.report(frame.info().frame_id, !split.two_classes, split.text());
    output_.emit(frame, in.area, residue, in.untrusted, in.unknown, in.depth_mm);
  }

 private:
  const ResidueIndex index_;
  const int min_value_;
  ResidueOutput output_;
  OneMaterialNotice notice_;
};

}  // namespace

StageDescriptor describe_color_index() {
  StageDescriptor d;
  d.type = "segmentation.color_index";
  d.summary = "residue mask from a colour index (excess green, ...) with Otsu's threshold";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      color_index_param(),   smoothing_px_param(), max_smoothing_px_param(), dilation_px_param(),
      segmented_roi_param(), speckle_px_param(1),  min_value_param(),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<ColorIndexStage>();
  return d;
}

TILTH_STAGE(describe_color_index());

}  // namespace tilth::segmentation
