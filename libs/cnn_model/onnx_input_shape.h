// The shape an ONNX model declares for its first input, read from the file's protobuf
// without a protobuf library (ModelProto.graph.input[0].type.tensor_type.shape), so that
// segmentation.cnn can hold the network to its sidecar: OpenCV's dnn runs a convolutional
// network at any input size and would not notice a mismatch.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace tilth::segmentation {

// Each dimension's value, -1 for a symbolic one. Throws tilth::Error naming the file when
// it cannot be read or is not an ONNX model with a tensor input.
std::vector<std::int64_t> onnx_input_shape(const std::filesystem::path& file);

}  // namespace tilth::segmentation
