// segmentation.depth_aided: residue is what stands above the soil, whatever its colour.
//
//   depth ──► 3x3 median ──► soil surface (the envelope of the farthest depths, then a
//   local Gaussian-weighted surface) ──► height above it > height_mm? ──► residue ──►
//   despeckle ──► dilate ──► mask, soil_depth
//   color: not read (the port is there so that a graph swaps the variants by name)
//
// Invariant: a pixel is soil only when it has depth and lies no more than height_mm above
// the surface fitted to the farthest depths; it is unknown when it has no depth (or, after
// the 3x3 median, most of its neighbours have none).
//
//   "segment": {"type": "segmentation.depth_aided", "params": {"height_mm": 3}}
#include <opencv2/core.hpp>

#include "residue_output.h"
#include "soil_surface/soil_surface.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

class DepthAided final : public Transform {
 public:
  explicit DepthAided(const StageContext& context)
      : surface_(context.params.number("height_mm"), context.params.number("max_height_mm"),
                 context.params.number("surface_px"), context.params.number("envelope_px")),
        output_(context.params) {}

  void process(Frame& frame) override {
    const auto& color = frame.input<RegisteredColor>(kColorInput);
    const auto& depth = frame.input<DepthImage>(kDepthInput);
    check_residue_inputs(color, depth);
    const cv::Rect area = output_.area(depth.mm.size());
    const cv::Mat depth_mm = depth.mm(area);

    thread_local cv::Mat missing, height, residue, unknown;
    mark_missing_depth(depth_mm, missing);
    const double residue_mm = surface_.heights(depth_mm, missing, ~missing, height);
    cv::compare(height, residue_mm, residue, cv::CMP_GT);  // NaN: no
    cv::compare(height, height, unknown, cv::CMP_NE);      // NaN: no surface near
    cv::bitwise_or(unknown, missing, unknown);
    output_.emit(frame, area, residue, unknown, unknown, depth_mm);
  }

 private:
  const SoilSurface surface_;
  ResidueOutput output_;
};

}  // namespace

StageDescriptor describe_depth_aided() {
  StageDescriptor d;
  d.type = "segmentation.depth_aided";
  d.summary = "residue mask from the height above a robust soil surface (depth only)";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {height_mm_param(),   max_height_mm_param(), surface_px_param(), envelope_px_param(),
              dilation_px_param(), segmented_roi_param(), speckle_px_param(1)};
  d.concurrency = Concurrency::kParallel;
  d.create = factory<DepthAided>();
  return d;
}

TILTH_STAGE(describe_depth_aided());

}  // namespace tilth::segmentation
