// segmentation.pixel_classifier with a forest trained by tilth train-segmenter's own code
// on painted frames: it classifies unseen frames as OpenCV's forest does on the features
// the trainer samples, pixel by pixel (so the stage and the trainer see the same
// features), and every kind of bad model file stops it with a message naming the file and
// what was expected.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "painted_frame.h"
#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/pixel_features.h"
#include "pixel_classifier/residue_classifier.h"
#include "segmenter_training.h"
#include "temp_dir.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;
using train_segmenter::RegisteredFrame;

const cv::Size kSize(96, 64);
constexpr float kSoilMm = 500.0f;
const std::vector<cv::Vec3b> kStraws = {{120, 190, 220}, {60, 95, 110}, {170, 215, 230}};
const std::vector<cv::Vec3b> kSoils = {{55, 80, 110}, {27, 40, 55}, {100, 125, 150}};

// Vertical bands of straw and soil colours with 3 DN of noise (seed `seed`), and the
// truth: residue on straw bands, unknown on the one-pixel boundary a 3x3 mean blurs.
RegisteredFrame banded_frame(int seed) {
  PaintedFrame painted(kSize, kSoils[0], kSoilMm);
  auto truth = std::make_shared<GroundTruth>();
  truth->residue_mask = cv::Mat(kSize, CV_8UC1, cv::Scalar(ResidueMask::kSoil));
  for (int band = 0; band < 6; ++band) {
    const cv::Rect area(band * 16, 0, 16, kSize.height);
    const bool straw = band % 2 == 0;
    painted.paint(area, straw ? kStraws[band / 2] : kSoils[band / 2]);
    if (straw) truth->residue_mask(area).setTo(ResidueMask::kResidue);
  }
  for (int edge = 16; edge < kSize.width; edge += 16) {
    truth->residue_mask(cv::Rect(edge - 1, 0, 2, kSize.height)).setTo(ResidueMask::kUnknown);
  }
  cv::Mat noise(kSize, CV_16SC3), noisy;
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  painted.color->bgr.convertTo(noisy, CV_16SC3);
  cv::Mat(noisy + noise).convertTo(painted.color->bgr, CV_8UC3);
  return {static_cast<std::uint64_t>(seed), painted.color, painted.depth, truth};
}

class TrainedModel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    train_segmenter::TrainingSet training(FeatureSet::kTexture);
    for (int seed = 1; seed <= 3; ++seed) training.sample(banded_frame(seed), 500, seed);
    model_ = training.train({ClassifierKind::kForest, 20, 8}, "painted bands, seeds 1-3");
    write_classifier_model(model(), model_);
  }
  static void TearDownTestSuite() { model_.trees.release(); }
  static std::filesystem::path model() { return directory().path() / "bands.yml.gz"; }
  static const testing::TempDir& directory() {
    static const testing::TempDir temp;
    return temp;
  }
  static ClassifierModel model_;
};

ClassifierModel TrainedModel::model_;

TEST_F(TrainedModel, ClassifiesAnUnseenFrameAsTheForestDoes) {
  const RegisteredFrame frame = banded_frame(9);
  PaintedFrame painted(kSize, kSoils[0], kSoilMm);
  painted.color = std::const_pointer_cast<RegisteredColor>(frame.color);
  const Segmented out = segment(
      describe_pixel_classifier(),
      {{"model", model().string()}, {"scored_every_px", 1}, {"dilation_px", 0}, {"speckle_px", 0}},
      painted);
  // The features as the trainer samples them: every pixel is trusted in a painted frame.
  cv::Mat features;
  pixel_features(FeatureSet::kTexture, frame.color->bgr,
                 frame.color->status == RegisteredColor::kValid, features);
  int disagreements = 0, errors = 0, judged = 0;
  for (int row = 0; row < kSize.height; ++row) {
    for (int col = 0; col < kSize.width; ++col) {
      const bool forest_says_residue =
          model_.trees->predict(features.row(row * kSize.width + col)) ==
          static_cast<float>(kResidueClass);
      const bool stage_says_residue = out.mask.at<std::uint8_t>(row, col) == ResidueMask::kResidue;
      disagreements += forest_says_residue != stage_says_residue;
      const std::uint8_t truth = frame.truth->residue_mask.at<std::uint8_t>(row, col);
      if (truth == ResidueMask::kUnknown) continue;
      ++judged;
      errors += stage_says_residue != (truth == ResidueMask::kResidue);
    }
  }
  EXPECT_EQ(disagreements, 0);
  // The shadowed straw (60, 95, 110) and the brown soil (55, 80, 110) lie 15 DN apart in
  // green; with 3 DN of noise on each channel a few pixels in a thousand land nearer the
  // other colour.
  EXPECT_LE(errors, judged / 500) << "of " << judged;
}

// Scoring every 2nd pixel of every 2nd row changes a decision only where the scored pixels
// around it agree with each other: every boundary between them is refined.
TEST_F(TrainedModel, ScoringAGridDiffersOnlyInsideAgreeingCells) {
  const RegisteredFrame frame = banded_frame(9);
  const cv::Rect whole({}, kSize);
  const cv::Mat trusted = frame.color->status == RegisteredColor::kValid;
  cv::Mat every, grid;
  ResidueClassifier(model_, 1).classify(frame.color->bgr, whole, trusted, every);
  ResidueClassifier(model_, 2).classify(frame.color->bgr, whole, trusted, grid);
  // The scored rows (columns) around a row (column): itself, or the ones on either side.
  const auto around = [](int index, int count) {
    return index % 2 == 0 || index == count - 1 ? std::vector<int>{index}
                                                : std::vector<int>{index - 1, index + 1};
  };
  int differing = 0;
  for (int row = 0; row < kSize.height; ++row) {
    for (int col = 0; col < kSize.width; ++col) {
      if (every.at<std::uint8_t>(row, col) == grid.at<std::uint8_t>(row, col)) continue;
      ++differing;
      const std::vector<int> rows = around(row, kSize.height), cols = around(col, kSize.width);
      ASSERT_GT(rows.size() + cols.size(), 2u) << "a scored pixel, " << row << ", " << col;
      for (const int r : rows) {
        for (const int c : cols) {
          EXPECT_EQ(every.at<std::uint8_t>(r, c), grid.at<std::uint8_t>(row, col))
              << "around " << row << ", " << col;
        }
      }
    }
  }
  // The bands' boundaries are where the decisions change: refined, all of them.
  EXPECT_LE(differing, kSize.area() / 200);
}

TEST_F(TrainedModel, ModelFileRecordsFormatFeaturesAndTraining) {
  cv::FileStorage storage(model().string(), cv::FileStorage::READ);
  EXPECT_EQ(storage["format"].string(), kClassifierFormat);
  EXPECT_EQ(storage["feature_set"].string(), "texture/1");
  EXPECT_EQ(storage["features"].size(), feature_names(FeatureSet::kTexture).size());
  EXPECT_EQ(storage["classifier"].string(), "forest");
  EXPECT_EQ(storage["training"].string(), "painted bands, seeds 1-3");
}

std::string construction_error(const std::filesystem::path& model) {
  try {
    testing::TransformHarness stage(describe_pixel_classifier(), {{"model", model.string()}});
  } catch (const Error& error) {
    return error.what();
  }
  return "constructed";
}

// A valid model file with one line replaced.
std::string edited_model(const std::string& from, const std::string& to) {
  testing::TempDir temp;
  const auto file = temp.path() / "model.yml";
  train_segmenter::TrainingSet training(FeatureSet::kColour);
  training.sample(banded_frame(1), 50, 1);
  write_classifier_model(file, training.train({ClassifierKind::kForest, 2, 2}, "tiny"));
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(PixelClassifierModel, MissingFile) {
  EXPECT_EQ(construction_error("/nonexistent/straw.yml"),
            "model file '/nonexistent/straw.yml': no such file (expected a model written by "
            "tilth train-segmenter)");
}

TEST(PixelClassifierModel, NotAModelFile) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", "%YAML:1.0\n---\nformat: [unclosed\n");
  const std::string error = construction_error(file);
  EXPECT_EQ(
      error.rfind("model file '" + file.string() + "': not an OpenCV YAML/XML/JSON file (", 0), 0u)
      << error;
}

// Format 1 (a forest over colour cells) is not read: its colour/1 set is trained anew.
TEST(PixelClassifierModel, AnotherFormatVersion) {
  testing::TempDir temp;
  const auto file =
      temp.write("straw.yml", edited_model("tilth-pixel-classifier/2", "tilth-pixel-classifier/1"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': format \"tilth-pixel-classifier/1\" (expected \"tilth-pixel-classifier/2\"; "
                "retrain with this version's tilth train-segmenter)");
}

TEST(PixelClassifierModel, UnknownFeatureSet) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", edited_model("colour/1", "colour/7"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': feature set \"colour/7\" (expected \"colour/1\" or \"texture/1\")");
}

TEST(PixelClassifierModel, UnknownClassifier) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", edited_model("classifier: forest", "classifier: svm"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() + "': classifier \"svm\" (expected forest or boosted)");
}

TEST(PixelClassifierModel, OtherFeatures) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", edited_model("- \"b*/L*\"", "- NDVI"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': features [L*, a*, b*, H, S, V, exg, a*/L*, NDVI] (expected [L*, a*, b*, H, S, "
                "V, exg, a*/L*, b*/L*] for \"colour/1\"; retrain with this version's tilth "
                "train-segmenter)");
}

TEST(PixelClassifierModel, NoTrees) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", edited_model("trees:", "woods:"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': no 'trees' (expected the forest written by tilth train-segmenter)");
}

// OpenCV would keep the first "training" and ignore the second.
TEST(PixelClassifierModel, DuplicateKey) {
  testing::TempDir temp;
  const auto file =
      temp.write("straw.yml", edited_model("training:", "training: \"a\"\ntraining:"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': /training: expected each key once in a map, got \"training\" again");
}

}  // namespace
}  // namespace tilth::segmentation
