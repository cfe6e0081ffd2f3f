// segmentation.pixel_classifier: residue as a trained classifier (a random forest or
// boosted trees from tilth train-segmenter) sees it, from each pixel's colour and, with
// the texture feature set, the luminance texture around it.
//
//   model file ──► trees, flattened (TreeEnsemble)
//   color ──► 3x3 mean ──► the model's feature set, planes over the area ──► score > 0 on
//   every scored_every_px-th pixel, and between them where they disagree ──► residue ──►
//   despeckle ──► dilate ──► mask, soil_depth
//
// Invariant: the classifier sees what it saw in training: ResidueClassifier computes the
// features with the code tilth train-segmenter samples them with, and scores them as the
// trees' own predict() does. The texture set's luminance is normalised by the median over
// the pixels whose colour is trusted in the segmented area; the features of that area's
// edge come from the image around it, as in a whole image.
//
//   "segment": {"type": "segmentation.pixel_classifier", "params": {"model": "straw.yml.gz"}}
#include <opencv2/core.hpp>

#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/residue_classifier.h"
#include "residue_output.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

class PixelClassifier final : public Transform {
 public:
  explicit PixelClassifier(const StageContext& context)
      : classifier_(read_classifier_model(context.params.path("model")),
                    static_cast<int>(context.params.integer("scored_every_px"))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        output_(context.params) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat trusted, residue;
    cv::bitwise_not(in.untrusted, trusted);
    classifier_.classify(frame.input<RegisteredColor>(kColorInput).bgr, in.area, trusted, residue);
    output_.emit(frame, in.area, residue, in.untrusted, in.unknown, in.depth_mm);
  }

 private:
  const ResidueClassifier classifier_;
  const int min_value_;
  ResidueOutput output_;
};

}  // namespace

StageDescriptor describe_pixel_classifier() {
  StageDescriptor d;
  d.type = "segmentation.pixel_classifier";
  d.summary = "residue mask from a trained pixel classifier (tilth train-segmenter's model)";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      ParamSpec::path("model", std::nullopt)
          .describe("model file written by tilth train-segmenter (" +
                    std::string(kClassifierFormat) + ")"),
      scored_every_px_param(),
      dilation_px_param(),
      segmented_roi_param(),
      speckle_px_param(1),
      min_value_param(),
  };
  d.concurrency = Concurrency::kParallel;
  d.create = factory<PixelClassifier>();
  return d;
}

TILTH_STAGE(describe_pixel_classifier());

}  // namespace tilth::segmentation
