// The sidecar of a segmentation.cnn model (MODEL.json beside MODEL.onnx), written by
// tilth train-segmenter's train_cnn.py: the network's input size, how a window of the
// depth grid becomes its input (colour order, scale, mean and standard deviation per
// channel), and the threshold on its output, so that the stage never guesses them
// (docs/segmentation-variants.md).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <string_view>

namespace tilth::segmentation {

inline constexpr std::string_view kCnnFormat = "tilth-cnn-segmenter/1";

struct CnnSidecar {
  int width = 0;  // the network's input, px
  int height = 0;
  // input = (colour * value_scale - mean[c]) / std[c], channels in R, G, B order
  double value_scale = 1.0 / 255.0;
  std::array<double, 3> mean{};
  std::array<double, 3> std{};
  double window_scale = 0.25;  // network px per depth px of the windows trained on
  double threshold = 0.5;      // residue where the network's probability exceeds it
  std::string training;        // free text for people
};

// MODEL.json for MODEL.onnx.
std::filesystem::path cnn_sidecar_path(const std::filesystem::path& onnx);

// Throws tilth::Error naming the file, the JSON pointer and what was expected: a missing
// or unreadable file, not JSON, another format, a missing or ill-typed value, a colour
// order other than rgb, a resize other than area.
CnnSidecar read_cnn_sidecar(const std::filesystem::path& file);

}  // namespace tilth::segmentation
