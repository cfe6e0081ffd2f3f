#include "cnn_model/onnx_input_shape.h"

#include <fstream>
#include <iterator>
#include <optional>
#include <string>
#include <string_view>

#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

// The protobuf field numbers on the way to the input's shape (onnx/onnx.proto).
constexpr std::uint64_t kModelGraph = 7;     // ModelProto.graph
constexpr std::uint64_t kGraphInput = 11;    // GraphProto.input, repeated
constexpr std::uint64_t kValueInfoType = 2;  // ValueInfoProto.type
constexpr std::uint64_t kTypeTensor = 1;     // TypeProto.tensor_type
constexpr std::uint64_t kTensorShape = 2;    // TypeProto.Tensor.shape
constexpr std::uint64_t kShapeDim = 1;       // TensorShapeProto.dim, repeated
constexpr std::uint64_t kDimValue = 1;       // Dimension.dim_value

enum WireType : std::uint64_t { kVarint = 0, kFixed64 = 1, kLength = 2, kFixed32 = 5 };

struct Field {
  std::uint64_t number = 0;
  std::uint64_t wire = 0;
  std::uint64_t varint = 0;  // kVarint
  std::string_view bytes;    // kLength
};

// The fields of one protobuf message, in order; nullopt at the end, throws at damage.
class Fields {
 public:
  explicit Fields(std::string_view message) : rest_(message) {}

  std::optional<Field> next() {
    if (rest_.empty()) return std::nullopt;
    Field field;
    const std::uint64_t key = varint();
    field.number = key >> 3;
    field.wire = key & 7;
    switch (field.wire) {
      case kVarint:
        field.varint = varint();
        break;
      case kFixed64:
        skip(8);
        break;
      case kFixed32:
        skip(4);
        break;
      case kLength: {
        const std::uint64_t length = varint();
        if (length > rest_.size()) throw Error("a field runs past its message's end");
        field.bytes = rest_.substr(0, length);
        rest_.remove_prefix(length);
        break;
      }
      default:
        throw Error("wire type " + std::to_string(field.wire) + " of field " +
                    std::to_string(field.number) + " (expected 0, 1, 2 or 5)");
    }
    return field;
  }

  // The first length-delimited field `number`, if any.
  static std::optional<std::string_view> first(std::string_view message, std::uint64_t number) {
    Fields fields(message);
    while (const auto field = fields.next()) {
      if (field->number == number && field->wire == kLength) return field->bytes;
    }
    return std::nullopt;
  }

 private:
  std::uint64_t varint() {
    std::uint64_t value = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      if (rest_.empty()) throw Error("a number runs past its message's end");
      const auto byte = static_cast<std::uint8_t>(rest_.front());
      rest_.remove_prefix(1);
      value |= static_cast<std::uint64_t>(byte & 0x7f) << shift;
      if ((byte & 0x80) == 0) return value;
    }
    throw Error("a number of more than 10 bytes");
  }

  void skip(std::size_t bytes) {
    if (bytes > rest_.size()) throw Error("a field runs past its message's end");
    rest_.remove_prefix(bytes);
  }

  std::string_view rest_;
};

}  // namespace

std::vector<std::int64_t> onnx_input_shape(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error("ONNX model '" + file.string() + "' cannot be read");
  const std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto fail = [&](const std::string& what) -> Error {
    return Error("ONNX model '" + file.string() + "': " + what +
                 " (expected an ONNX model whose first input is a tensor of known shape)");
  };
  try {
    const auto graph = Fields::first(content, kModelGraph);
    if (!graph) throw fail("no graph");
    const auto input = Fields::first(*graph, kGraphInput);
    if (!input) throw fail("the graph has no input");
    const auto type = Fields::first(*input, kValueInfoType);
    const auto tensor = type ? Fields::first(*type, kTypeTensor) : std::nullopt;
    const auto shape = tensor ? Fields::first(*tensor, kTensorShape) : std::nullopt;
    if (!shape) throw fail("the first input is not a tensor with a shape");
    std::vector<std::int64_t> dims;
    Fields fields(*shape);
    while (const auto dim = fields.next()) {
      if (dim->number != kShapeDim || dim->wire != kLength) continue;
      std::int64_t value = -1;
      Fields parts(dim->bytes);
      while (const auto part = parts.next()) {
        if (part->number == kDimValue && part->wire == kVarint) {
          value = static_cast<std::int64_t>(part->varint);
        }
      }
      dims.push_back(value);
    }
    return dims;
  } catch (const Error& error) {
    if (std::string_view(error.what()).starts_with("ONNX model")) throw;
    throw fail(std::string("damaged: ") + error.what());
  }
}

}  // namespace tilth::segmentation
