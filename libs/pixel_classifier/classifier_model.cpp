#include "pixel_classifier/classifier_model.h"

#include <set>

#include <opencv2/core/persistence.hpp>

#include "pixel_classifier/pixel_features.h"
#include "tilth/error.h"

namespace tilth::segmentation {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return "[" + text + "]";
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw Error("model file '" + file.string() + "': " + what);
}

// OpenCV keeps the first of two equal keys of a map and ignores the second: refused, as
// in every file Tilth reads, so that no value is silently other than written.
void refuse_duplicate_keys(const std::filesystem::path& file, const cv::FileNode& node,
                           const std::string& pointer) {
  if (!node.isMap() && !node.isSeq()) return;
  std::set<std::string> keys;
  std::size_t index = 0;
  for (const cv::FileNode& child : node) {
    const std::string where =
        pointer + "/" + (node.isMap() ? child.name() : std::to_string(index++));
    if (node.isMap() && !keys.insert(child.name()).second) {
      fail(file, where + ": expected each key once in a map, got \"" + child.name() + "\" again");
    }
    refuse_duplicate_keys(file, child, where);
  }
}

}  // namespace

void write_classifier_model(const std::filesystem::path& file, const cv::ml::RTrees& forest,
                            const std::string& training) {
  cv::FileStorage storage(file.string(), cv::FileStorage::WRITE);
  if (!storage.isOpened()) fail(file, "cannot be written");
  storage << "format" << std::string(kClassifierFormat);
  storage << "features"
          << "[";
  for (const auto& name : pixel_feature_names()) storage << name;
  storage << "]";
  storage << "cell_bits" << kCellBits;
  storage << "smoothing_px" << kFeatureSmoothingPx;
  storage << "classes"
          << "["
          << "soil"
          << "residue"
          << "]";
  storage << "training" << training;
  storage << "forest"
          << "{";
  forest.write(storage);
  storage << "}";
}

cv::Ptr<cv::ml::RTrees> read_classifier_model(const std::filesystem::path& file) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) {
    fail(file, "no such file (expected a model written by tilth train-segmenter)");
  }
  cv::FileStorage storage;
  try {
    if (!storage.open(file.string(), cv::FileStorage::READ)) fail(file, "cannot be read");
  } catch (const cv::Exception& exception) {
    fail(file, "not an OpenCV YAML/XML/JSON file (" + exception.msg + ")");
  }
  refuse_duplicate_keys(file, storage.root(), "");
  const cv::FileNode format = storage["format"];
  if (!format.isString())
    fail(file, "no 'format' (expected \"" + std::string(kClassifierFormat) + "\")");
  if (format.string() != kClassifierFormat) {
    fail(file, "format \"" + format.string() + "\" (expected \"" + std::string(kClassifierFormat) +
                   "\"; retrain with this version's tilth train-segmenter)");
  }
  std::vector<std::string> features;
  if (storage["features"].isSeq()) {
    for (const auto& name : storage["features"])
      features.push_back(name.isString() ? name.string() : "?");
  }
  if (features != pixel_feature_names()) {
    fail(file, "features " + joined(features) + " (expected " + joined(pixel_feature_names()) +
                   "; retrain with this version's tilth train-segmenter)");
  }
  std::vector<std::string> classes;
  if (storage["classes"].isSeq()) {
    for (const auto& name : storage["classes"])
      classes.push_back(name.isString() ? name.string() : "?");
  }
  if (classes != std::vector<std::string>{"soil", "residue"}) {
    fail(file, "classes " + joined(classes) + " (expected [soil, residue], labels 0 and 1)");
  }
  const int cell_bits = storage["cell_bits"].isInt() ? static_cast<int>(storage["cell_bits"]) : -1;
  const int smoothing =
      storage["smoothing_px"].isInt() ? static_cast<int>(storage["smoothing_px"]) : -1;
  if (cell_bits != kCellBits || smoothing != kFeatureSmoothingPx) {
    fail(file, "colour cells of " + std::to_string(cell_bits) + " bits after " +
                   std::to_string(smoothing) + " px smoothing (expected " +
                   std::to_string(kCellBits) + " bits after " +
                   std::to_string(kFeatureSmoothingPx) + " px)");
  }
  if (!storage["forest"].isMap()) {
    fail(file, "no 'forest' (expected the random forest written by tilth train-segmenter)");
  }
  cv::Ptr<cv::ml::RTrees> forest = cv::ml::RTrees::create();
  try {
    forest->read(storage["forest"]);
  } catch (const cv::Exception& exception) {
    fail(file, "the 'forest' cannot be read (" + exception.msg + ")");
  }
  if (!forest->isTrained() || !forest->isClassifier() ||
      forest->getVarCount() != static_cast<int>(features.size())) {
    fail(file, "no trained random forest classifier of " + std::to_string(features.size()) +
                   " features under 'forest'");
  }
  return forest;
}

std::vector<std::uint8_t> residue_by_cell(const cv::ml::StatModel& classifier) {
  cv::Mat classes;
  classifier.predict(cell_features(), classes);
  std::vector<std::uint8_t> residue(kCellCount);
  for (int cell = 0; cell < kCellCount; ++cell) {
    residue[cell] = classes.at<float>(cell) == kResidueClass ? 255 : 0;
  }
  return residue;
}

}  // namespace tilth::segmentation
