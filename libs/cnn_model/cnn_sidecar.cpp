#include "cnn_model/cnn_sidecar.h"

#include <fstream>

#include <nlohmann/json.hpp>

#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;

class SidecarReader {
 public:
  explicit SidecarReader(std::filesystem::path file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& what) const {
    throw Error("model sidecar '" + file_.string() + "'" +
                (pointer.empty() ? "" : " at " + pointer) + ": " + what);
  }

  const json& at(const json& document, const std::string& pointer, const char* expected) const {
    const json::json_pointer where(pointer);
    if (!document.contains(where))
      fail(pointer, std::string("missing (expected ") + expected + ")");
    return document.at(where);
  }

  double number(const json& document, const std::string& pointer, double low, double high) const {
    const std::string expected =
        "a number in [" + json(low).dump() + ", " + json(high).dump() + "]";
    const json& value = at(document, pointer, expected.c_str());
    if (!value.is_number() || value.get<double>() < low || value.get<double>() > high) {
      fail(pointer, "expected " + expected + ", got " + value.dump());
    }
    return value.get<double>();
  }

  int size(const json& document, const std::string& pointer) const {
    const json& value = at(document, pointer, "a multiple of 4 in [8, 4096]");
    if (!value.is_number_integer() || value.get<int>() < 8 || value.get<int>() > 4096 ||
        value.get<int>() % 4 != 0) {
      fail(pointer, "expected a multiple of 4 in [8, 4096] (two poolings), got " + value.dump());
    }
    return value.get<int>();
  }

  void text(const json& document, const std::string& pointer, const std::string& expected) const {
    const json& value = at(document, pointer, ("\"" + expected + "\"").c_str());
    if (value != expected) fail(pointer, "expected \"" + expected + "\", got " + value.dump());
  }

  std::array<double, 3> triple(const json& document, const std::string& pointer, double low,
                               double high) const {
    const json& value = at(document, pointer, "3 numbers, R G B");
    if (!value.is_array() || value.size() != 3) {
      fail(pointer, "expected 3 numbers, R G B, got " + value.dump());
    }
    std::array<double, 3> numbers{};
    for (std::size_t c = 0; c < 3; ++c) {
      numbers[c] = number(document, pointer + "/" + std::to_string(c), low, high);
    }
    return numbers;
  }

 private:
  const std::filesystem::path file_;
};

}  // namespace

std::filesystem::path cnn_sidecar_path(const std::filesystem::path& onnx) {
  return std::filesystem::path(onnx).replace_extension(".json");
}

CnnSidecar read_cnn_sidecar(const std::filesystem::path& file) {
  const SidecarReader reader(file);
  std::ifstream in(file);
  if (!in) {
    reader.fail("", "cannot be read (expected the " + std::string(kCnnFormat) +
                        " file that tilth train-segmenter --model cnn writes beside the .onnx)");
  }
  json document;
  try {
    document = json::parse(in);
  } catch (const json::parse_error& error) {
    reader.fail("", std::string("not JSON (") + error.what() + ")");
  }
  if (!document.is_object()) reader.fail("", "expected a JSON object, got " + document.dump());
  const json& format =
      reader.at(document, "/format", ("\"" + std::string(kCnnFormat) + "\"").c_str());
  if (format != kCnnFormat) {
    reader.fail("/format", "expected \"" + std::string(kCnnFormat) + "\", got " + format.dump() +
                               " (a model of another kind or version: retrain with this version's "
                               "tilth train-segmenter --model cnn)");
  }
  CnnSidecar sidecar;
  sidecar.width = reader.size(document, "/input/width");
  sidecar.height = reader.size(document, "/input/height");
  reader.text(document, "/input/colour_order", "rgb");
  reader.text(document, "/input/resize", "area");
  sidecar.value_scale = reader.number(document, "/input/scale", 1e-6, 1.0);
  sidecar.mean = reader.triple(document, "/input/mean", -1e3, 1e3);
  sidecar.std = reader.triple(document, "/input/std", 1e-6, 1e3);
  sidecar.window_scale = reader.number(document, "/window_scale", 0.01, 1.0);
  sidecar.threshold = reader.number(document, "/output/threshold", 0.0, 1.0);
  if (document.contains("training") && document["training"].is_string()) {
    sidecar.training = document["training"].get<std::string>();
  }
  return sidecar;
}

}  // namespace tilth::segmentation
