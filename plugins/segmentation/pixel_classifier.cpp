// segmentation.pixel_classifier: residue as a trained classifier (a random forest from
// tilth train-segmenter) sees it, from each pixel's colour.
//
//   model file ──► forest ──► the class of every colour cell (at start: 262 144 cells)
//   color ──► 3x3 mean, 6 bits per channel ──► cell ──► class ──► residue ──► despeckle ──►
//   dilate ──► mask, soil_depth
//
// Invariant: the classifier sees exactly what it saw in training (pixel_features.h): the
// colour cell of the pixel, described by the features of the cell's centre. So the class
// of every cell can be looked up instead of running the forest per pixel, and the lookup
// gives what the forest gives.
//
//   "segment": {"type": "segmentation.pixel_classifier", "params": {"model": "straw.yml.gz"}}
#include <opencv2/core.hpp>

#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/pixel_features.h"
#include "residue_output.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

class PixelClassifier final : public Transform {
 public:
  explicit PixelClassifier(const StageContext& context)
      : residue_by_cell_(residue_by_cell(*read_classifier_model(context.params.path("model")))),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        output_(context.params) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat cells, residue;
    color_cells(in.bgr, cells);
    residue.create(cells.size(), CV_8UC1);
    for (int row = 0; row < cells.rows; ++row) {
      const auto* cell = cells.ptr<std::int32_t>(row);
      auto* out = residue.ptr<std::uint8_t>(row);
      for (int col = 0; col < cells.cols; ++col) out[col] = residue_by_cell_[cell[col]];
    }
    output_.emit(frame, in.area, residue, in.untrusted, in.unknown, in.depth_mm);
  }

 private:
  const std::vector<std::uint8_t> residue_by_cell_;
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
