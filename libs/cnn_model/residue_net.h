// A segmentation.cnn model at work: MODEL.onnx read by OpenCV's dnn module (its own CPU
// backend), held to its sidecar, and run on a window of a registered colour image to give
// the residue probability and mask. The stage and tilth train-segmenter's scores both use
// it, so a model is scored as the stage will run it.
#pragma once

#include <filesystem>

#include <opencv2/core/mat.hpp>
#include <opencv2/dnn.hpp>

#include "cnn_model/cnn_sidecar.h"

namespace tilth::segmentation {

class ResidueNet {
 public:
  // Reads `onnx` and its sidecar (cnn_sidecar_path) and runs the network once on a blank
  // input. Throws tilth::Error naming the file and what was expected: a missing file, a
  // sidecar as read_cnn_sidecar refuses it, an input other than 1x3x(sidecar's height)x
  // (its width), a file OpenCV cannot read or run, an output other than one channel of the
  // input's size.
  explicit ResidueNet(const std::filesystem::path& onnx);

  const CnnSidecar& sidecar() const { return sidecar_; }

  // The network's input (1x3xHxW CV_32F) from a CV_8UC3 BGR window of any size: in float,
  // area-averaged to the input size, channels in R, G, B order, (value * scale - mean) / std.
  void prepare(const cv::Mat& bgr, cv::Mat& blob) const;

  // The residue probability at the network's input size (CV_32FC1).
  void probabilities(const cv::Mat& bgr, cv::Mat& probability);

  // 255 residue, 0 soil for every pixel of the window (CV_8UC1 of its size): the
  // probability resized to the window bilinearly, above the sidecar's threshold.
  void classify(const cv::Mat& bgr, cv::Mat& residue);

 private:
  void forward(const cv::Mat& blob, cv::Mat& probability);

  std::filesystem::path file_;
  CnnSidecar sidecar_;
  cv::dnn::Net net_;
  cv::Mat blob_, probability_, window_probability_;
};

}  // namespace tilth::segmentation
