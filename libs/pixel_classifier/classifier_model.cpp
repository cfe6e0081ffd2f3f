#include "pixel_classifier/classifier_model.h"

#include <set>
#include <vector>

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

std::string_view classifier_kind_name(ClassifierKind kind) {
  return kind == ClassifierKind::kForest ? "forest" : "boosted";
}

ClassifierKind classifier_kind_named(std::string_view name) {
  if (name == "forest") return ClassifierKind::kForest;
  if (name == "boosted") return ClassifierKind::kBoosted;
  throw Error("classifier \"" + std::string(name) + "\" (expected forest or boosted)");
}

void write_classifier_model(const std::filesystem::path& file, const ClassifierModel& model) {
  cv::FileStorage storage(file.string(), cv::FileStorage::WRITE);
  if (!storage.isOpened()) fail(file, "cannot be written");
  storage << "format" << std::string(kClassifierFormat);
  storage << "feature_set" << std::string(feature_set_id(model.features));
  storage << "features"
          << "[";
  for (const auto& name : feature_names(model.features)) storage << name;
  storage << "]";
  storage << "smoothing_px" << kFeatureSmoothingPx;
  storage << "classifier" << std::string(classifier_kind_name(model.kind));
  storage << "classes"
          << "["
          << "soil"
          << "residue"
          << "]";
  storage << "training" << model.training;
  storage << "trees"
          << "{";
  model.trees->write(storage);
  storage << "}";
}

ClassifierModel read_classifier_model(const std::filesystem::path& file) {
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
  ClassifierModel model;
  const cv::FileNode set = storage["feature_set"];
  try {
    model.features = feature_set_of(set.isString() ? set.string() : "");
    const cv::FileNode kind = storage["classifier"];
    model.kind = classifier_kind_named(kind.isString() ? kind.string() : "");
  } catch (const Error& unknown) {
    fail(file, unknown.what());
  }
  std::vector<std::string> features;
  if (storage["features"].isSeq()) {
    for (const auto& name : storage["features"])
      features.push_back(name.isString() ? name.string() : "?");
  }
  const std::vector<std::string>& expected = feature_names(model.features);
  if (features != expected) {
    fail(file, "features " + joined(features) + " (expected " + joined(expected) + " for \"" +
                   std::string(feature_set_id(model.features)) +
                   "\"; retrain with this version's tilth train-segmenter)");
  }
  std::vector<std::string> classes;
  if (storage["classes"].isSeq()) {
    for (const auto& name : storage["classes"])
      classes.push_back(name.isString() ? name.string() : "?");
  }
  if (classes != std::vector<std::string>{"soil", "residue"}) {
    fail(file, "classes " + joined(classes) + " (expected [soil, residue], labels 0 and 1)");
  }
  const int smoothing =
      storage["smoothing_px"].isInt() ? static_cast<int>(storage["smoothing_px"]) : -1;
  if (smoothing != kFeatureSmoothingPx) {
    fail(file, "colours smoothed over " + std::to_string(smoothing) + " px (expected " +
                   std::to_string(kFeatureSmoothingPx) + " px)");
  }
  const std::string kind(classifier_kind_name(model.kind));
  if (!storage["trees"].isMap()) {
    fail(file, "no 'trees' (expected the " + kind + " written by tilth train-segmenter)");
  }
  if (model.kind == ClassifierKind::kForest) {
    model.trees = cv::ml::RTrees::create();
  } else {
    model.trees = cv::ml::Boost::create();
  }
  try {
    model.trees->read(storage["trees"]);
  } catch (const cv::Exception& exception) {
    fail(file, "the 'trees' cannot be read (" + exception.msg + ")");
  }
  if (!model.trees->isTrained() || !model.trees->isClassifier() ||
      model.trees->getVarCount() != static_cast<int>(features.size())) {
    fail(file, "no trained " + kind + " classifier of " + std::to_string(features.size()) +
                   " features under 'trees'");
  }
  const cv::FileNode training = storage["training"];
  model.training = training.isString() ? training.string() : "";
  return model;
}

}  // namespace tilth::segmentation
