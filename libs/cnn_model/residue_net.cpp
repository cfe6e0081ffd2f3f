#include "cnn_model/residue_net.h"

#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "cnn_model/onnx_input_shape.h"
#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

std::string shape_text(const std::vector<std::int64_t>& dims) {
  std::string text;
  for (const auto dim : dims)
    text += (text.empty() ? "" : "x") + (dim < 0 ? "?" : std::to_string(dim));
  return text;
}

}  // namespace

ResidueNet::ResidueNet(const std::filesystem::path& onnx) : file_(onnx) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(onnx, error)) {
    throw Error("model '" + onnx.string() +
                "': no such file (expected an ONNX file written by tilth train-segmenter "
                "--model cnn)");
  }
  sidecar_ = read_cnn_sidecar(cnn_sidecar_path(onnx));
  const std::vector<std::int64_t> shape = onnx_input_shape(onnx);
  const std::vector<std::int64_t> expected{1, 3, sidecar_.height, sidecar_.width};
  if (shape != expected) {
    throw Error("model '" + onnx.string() + "': its input is " + shape_text(shape) + " (expected " +
                shape_text(expected) + ", the size its sidecar '" +
                cnn_sidecar_path(onnx).string() + "' gives at /input/width and /input/height)");
  }
  try {
    net_ = cv::dnn::readNetFromONNX(onnx.string());
  } catch (const cv::Exception& exception) {
    throw Error("model '" + onnx.string() + "': OpenCV's dnn cannot read it (" + exception.msg +
                ")");
  }
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const int dims[] = {1, 3, sidecar_.height, sidecar_.width};
  forward(cv::Mat(4, dims, CV_32F, cv::Scalar(0)), probability_);
}

void ResidueNet::prepare(const cv::Mat& bgr, cv::Mat& blob) const {
  CV_Assert(bgr.type() == CV_8UC3 && !bgr.empty());
  thread_local cv::Mat values, resized;
  bgr.convertTo(values, CV_32FC3);
  cv::resize(values, resized, cv::Size(sidecar_.width, sidecar_.height), 0, 0, cv::INTER_AREA);
  const int dims[] = {1, 3, sidecar_.height, sidecar_.width};
  blob.create(4, dims, CV_32F);
  const cv::Size size(sidecar_.width, sidecar_.height);
  cv::Mat planes[3];
  for (int c = 0; c < 3; ++c) planes[c] = cv::Mat(size, CV_32FC1, blob.ptr<float>(0, c));
  // Channel c of the blob is R, G, B: BGR's channel 2 - c.
  cv::Mat bgr_planes[3] = {planes[2], planes[1], planes[0]};
  cv::split(resized, bgr_planes);
  for (int c = 0; c < 3; ++c) {
    planes[c].convertTo(planes[c], CV_32F, sidecar_.value_scale / sidecar_.std[c],
                        -sidecar_.mean[c] / sidecar_.std[c]);
  }
}

void ResidueNet::forward(const cv::Mat& blob, cv::Mat& probability) {
  cv::Mat output;
  try {
    net_.setInput(blob);
    output = net_.forward();
  } catch (const cv::Exception& exception) {
    throw Error("model '" + file_.string() + "': OpenCV's dnn cannot run it on a 1x3x" +
                std::to_string(sidecar_.height) + "x" + std::to_string(sidecar_.width) +
                " input (" + exception.msg + ")");
  }
  if (output.dims != 4 || output.size[0] != 1 || output.size[1] != 1 ||
      output.size[2] != sidecar_.height || output.size[3] != sidecar_.width) {
    std::string got;
    for (int d = 0; d < output.dims; ++d) got += (d ? "x" : "") + std::to_string(output.size[d]);
    throw Error("model '" + file_.string() + "': its output is " + got + " (expected 1x1x" +
                std::to_string(sidecar_.height) + "x" + std::to_string(sidecar_.width) +
                ", the residue probability of each input pixel)");
  }
  cv::Mat(sidecar_.height, sidecar_.width, CV_32FC1, output.ptr<float>()).copyTo(probability);
}

void ResidueNet::probabilities(const cv::Mat& bgr, cv::Mat& probability) {
  prepare(bgr, blob_);
  forward(blob_, probability);
}

void ResidueNet::classify(const cv::Mat& bgr, cv::Mat& residue) {
  probabilities(bgr, probability_);
  cv::resize(probability_, window_probability_, bgr.size(), 0, 0, cv::INTER_LINEAR);
  cv::compare(window_probability_, sidecar_.threshold, residue, cv::CMP_GT);
}

}  // namespace tilth::segmentation
