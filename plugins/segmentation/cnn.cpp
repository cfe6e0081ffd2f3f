// segmentation.cnn: residue as a small convolutional network (a U-Net that tilth
// train-segmenter --model cnn trains with PyTorch and exports as ONNX) sees it, from the
// colour and the context around each pixel.
//
//   MODEL.onnx + MODEL.json (sidecar: input size, colour order, mean/std, threshold)
//   color in the segmented area ──► float, area-averaged to the network's input ──►
//   (value/255 - mean) / std, RGB ──► OpenCV dnn ──► residue probability ──► bilinear to
//   the area ──► > threshold ──► residue ──► despeckle ──► dilate ──► mask, soil_depth
//
// Invariant: the network gets the input it was trained on, prepared as the sidecar says
// (ResidueNet::prepare, held to train_cnn.py's `prepare` by test cnn_agreement); nothing
// about the preparation is guessed here. The whole area is one input: the network sees it
// at the sidecar's window_scale when the area is width/window_scale x height/window_scale
// depth pixels (336x256 for the default 84x64 at 0.25, the chain's middle half of a 640x480
// frame with its margin); another size is seen at another scale.
//
// Threads: OpenCV's dnn runs its layers with cv::parallel_for_, which this OpenCV runs on
// oneTBB's workers, the pool the runtime's flow graph draws on: the stage starts no thread
// of its own and sets no global thread count (the benchmarks measure it with
// cv::setNumThreads(0), one core). The network keeps state between calls, so frames go
// through it one at a time.
//
//   "segment": {"type": "segmentation.cnn", "params": {"model": "straw.onnx",
//               "roi": "middle_half"}}
#include <opencv2/core.hpp>

#include "cnn_model/residue_net.h"
#include "residue_output.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

class Cnn final : public Transform {
 public:
  explicit Cnn(const StageContext& context)
      : net_(context.params.path("model")),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        output_(context.params) {}

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    net_.classify(in.bgr, residue_);
    output_.emit(frame, in.area, residue_, in.untrusted, in.unknown, in.depth_mm);
  }

 private:
  ResidueNet net_;
  const int min_value_;
  ResidueOutput output_;
  cv::Mat residue_;
};

}  // namespace

StageDescriptor describe_cnn() {
  StageDescriptor d;
  d.type = "segmentation.cnn";
  d.summary = "residue mask from a small convolutional network (tilth train-segmenter --model cnn)";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      ParamSpec::path("model", std::nullopt)
          .describe("ONNX file written by tilth train-segmenter --model cnn, its sidecar (" +
                    std::string(kCnnFormat) + ") beside it with .json for .onnx"),
      dilation_px_param(),
      segmented_roi_param(),
      speckle_px_param(1),
      min_value_param(),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<Cnn>();
  return d;
}

TILTH_STAGE(describe_cnn());

}  // namespace tilth::segmentation
