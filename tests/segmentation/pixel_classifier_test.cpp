// segmentation.pixel_classifier with a forest trained by tilth train-segmenter's own code
// on painted frames: it classifies unseen frames as the forest does, pixel by pixel, and
// every kind of bad model file stops it with a message naming the file and what was
// expected.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "painted_frame.h"
#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/pixel_features.h"
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
    train_segmenter::TrainingSet training;
    for (int seed = 1; seed <= 3; ++seed) training.sample(banded_frame(seed), 500, seed);
    forest_ = training.train(20, 8);
    write_classifier_model(model(), *forest_, "painted bands, seeds 1-3");
  }
  static void TearDownTestSuite() { forest_.release(); }
  static std::filesystem::path model() { return directory().path() / "bands.yml.gz"; }
  static const testing::TempDir& directory() {
    static const testing::TempDir temp;
    return temp;
  }
  static cv::Ptr<cv::ml::RTrees> forest_;
};

cv::Ptr<cv::ml::RTrees> TrainedModel::forest_;

TEST_F(TrainedModel, ClassifiesAnUnseenFrameAsTheForestDoes) {
  const RegisteredFrame frame = banded_frame(9);
  PaintedFrame painted(kSize, kSoils[0], kSoilMm);
  painted.color = std::const_pointer_cast<RegisteredColor>(frame.color);
  const Segmented out =
      segment(describe_pixel_classifier(),
              {{"model", model().string()}, {"dilation_px", 0}, {"speckle_px", 0}}, painted);
  cv::Mat cells;
  color_cells(frame.color->bgr, cells);
  int disagreements = 0, errors = 0, judged = 0;
  for (int row = 0; row < kSize.height; ++row) {
    for (int col = 0; col < kSize.width; ++col) {
      const int cell = cells.at<std::int32_t>(row, col);
      const bool forest_says_residue =
          forest_->predict(cell_features().row(cell)) == static_cast<float>(kResidueClass);
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
  // other colour (3 of 5504 here).
  EXPECT_LE(errors, judged / 500) << "of " << judged;
}

TEST_F(TrainedModel, ModelFileRecordsFormatFeaturesAndTraining) {
  cv::FileStorage storage(model().string(), cv::FileStorage::READ);
  EXPECT_EQ(storage["format"].string(), kClassifierFormat);
  EXPECT_EQ(storage["features"].size(), pixel_feature_names().size());
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
  train_segmenter::TrainingSet training;
  training.sample(banded_frame(1), 50, 1);
  write_classifier_model(file, *training.train(2, 2), "tiny");
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

TEST(PixelClassifierModel, AnotherFormatVersion) {
  testing::TempDir temp;
  const auto file =
      temp.write("straw.yml", edited_model("tilth-pixel-classifier/1", "tilth-pixel-classifier/2"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': format \"tilth-pixel-classifier/2\" (expected \"tilth-pixel-classifier/1\"; "
                "retrain with this version's tilth train-segmenter)");
}

TEST(PixelClassifierModel, OtherFeatures) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", edited_model("- \"b*/L*\"", "- NDVI"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': features [L*, a*, b*, H, S, V, exg, a*/L*, NDVI] (expected [L*, a*, b*, H, S, "
                "V, exg, a*/L*, b*/L*]; retrain with this version's tilth train-segmenter)");
}

TEST(PixelClassifierModel, NoForest) {
  testing::TempDir temp;
  const auto file = temp.write("straw.yml", edited_model("forest:", "woods:"));
  EXPECT_EQ(construction_error(file),
            "model file '" + file.string() +
                "': no 'forest' (expected the random forest written by tilth train-segmenter)");
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
