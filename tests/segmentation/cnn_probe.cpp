// The C++ side of test_cnn_agreement.py: a segmentation.cnn model run on an image file as
// the stage runs it.
//
//   cnn_probe probabilities MODEL.onnx IMAGE.png OUT.f32   the network's residue
//       probability (ResidueNet::probabilities: the stage's preparation and OpenCV's dnn),
//       raw float32, row by row, at the network's input size
//   cnn_probe stage MODEL.onnx IMAGE.png OUT.png           segmentation.cnn's mask of the
//       image (every colour trusted, depth 500 mm, no despeckling or dilation)
//
// Exit code 1 and the error on standard error when the model is refused.
#include <fstream>
#include <iostream>
#include <memory>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "cnn_model/residue_net.h"
#include "tilth/messages/depth_image.h"
#include "tilth/messages/registered_color.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/testing/stage_harness.h"
#include "variants.h"

namespace {

using namespace tilth;

void probabilities(const std::string& model, const cv::Mat& bgr, const std::string& out) {
  segmentation::ResidueNet net(model);
  cv::Mat probability;
  net.probabilities(bgr, probability);
  std::ofstream file(out, std::ios::binary);
  file.write(reinterpret_cast<const char*>(probability.ptr<float>()),
             static_cast<std::streamsize>(probability.total() * sizeof(float)));
  if (!file) throw Error("cannot write " + out);
}

void stage(const std::string& model, const cv::Mat& bgr, const std::string& out) {
  testing::TransformHarness harness(segmentation::describe_cnn(),
                                    {{"model", model}, {"dilation_px", 0}, {"speckle_px", 0}});
  auto color = std::make_shared<RegisteredColor>();
  color->bgr = bgr;
  color->status = cv::Mat(bgr.size(), CV_8UC1, cv::Scalar(RegisteredColor::kValid));
  auto depth = std::make_shared<DepthImage>();
  depth->mm = cv::Mat(bgr.size(), CV_32FC1, cv::Scalar(500.0f));
  const auto outputs = harness.run({color, depth});
  if (!cv::imwrite(out, outputs[0].get<ResidueMask>().values)) throw Error("cannot write " + out);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: cnn_probe probabilities|stage MODEL.onnx IMAGE.png OUT\n";
    return 2;
  }
  const std::string mode = argv[1];
  try {
    const cv::Mat bgr = cv::imread(argv[3], cv::IMREAD_COLOR);
    if (bgr.empty()) throw Error(std::string("cannot read the image ") + argv[3]);
    if (mode == "probabilities") {
      probabilities(argv[2], bgr, argv[4]);
    } else if (mode == "stage") {
      stage(argv[2], bgr, argv[4]);
    } else {
      std::cerr << "cnn_probe: mode " << mode << " (expected probabilities or stage)\n";
      return 2;
    }
  } catch (const std::exception& error) {
    std::cerr << "cnn_probe: " << error.what() << "\n";
    return 1;
  }
  return 0;
}
