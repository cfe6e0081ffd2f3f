// Every segmentation variant on frames of the scene simulator (rendered, projected and
// registered in process), against the simulator's ground truth: mask IoU, and the ground
// distance the paper's estimator would report from the soil depth (the median in the
// middle half of the image). The thresholds are the measured figures with a margin; the
// comments give the measurements (docs/segmentation-variants.md has the full table).
#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "color_threshold.h"
#include "pixel_classifier/classifier_model.h"
#include "pixel_classifier/residue_classifier.h"
#include "segmenter_training.h"
#include "simulated_frames.h"
#include "temp_dir.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/testing/stage_harness.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;
using train_segmenter::RegisteredFrame;

constexpr int kFrames = 2;

struct Outcome {
  double iou = 1;            // worst frame: residue IoU of the undilated mask
  double error_mm = 0;       // worst frame: |estimated - true distance|, when measurable
  double soil_fraction = 1;  // least soil fraction of the region of interest
};

// The region of interest of estimation.ground_distance: the middle half in each direction.
cv::Rect middle_half(const cv::Size& size) {
  return {size.width / 4, size.height / 4, size.width / 2, size.height / 2};
}

double median_depth(const cv::Mat& soil_mm, std::size_t& count) {
  std::vector<float> depths;
  for (int row = 0; row < soil_mm.rows; ++row) {
    for (int col = 0; col < soil_mm.cols; ++col) {
      const float depth = soil_mm.at<float>(row, col);
      if (!std::isnan(depth)) depths.push_back(depth);
    }
  }
  count = depths.size();
  if (depths.empty()) return std::nan("");
  std::sort(depths.begin(), depths.end());
  const std::size_t half = depths.size() / 2;
  return depths.size() % 2 ? depths[half] : 0.5 * (depths[half - 1] + depths[half]);
}

Outcome evaluate(const std::string& name, const StageDescriptor& stage, const json& params,
                 const std::vector<RegisteredFrame>& frames) {
  json undilated = params;
  undilated["dilation_px"] = 0;
  testing::TransformHarness classify(stage, undilated);
  testing::TransformHarness measure(stage, params);
  Outcome outcome;
  for (const RegisteredFrame& frame : frames) {
    const cv::Mat& truth = frame.truth->residue_mask;
    const auto classified = classify.run({frame.color, frame.depth}, frame.frame_id);
    const cv::Mat& mask = classified[0].get<ResidueMask>().values;
    const cv::Mat judged = (truth != ResidueMask::kUnknown) & (mask != ResidueMask::kUnknown);
    const cv::Mat said = mask == ResidueMask::kResidue;
    const cv::Mat is = truth == ResidueMask::kResidue;
    const int both = cv::countNonZero(said & is & judged);
    const int either = cv::countNonZero((said | is) & judged);
    const double iou = either == 0 ? 1.0 : static_cast<double>(both) / either;

    const auto measured = measure.run({frame.color, frame.depth}, frame.frame_id);
    const cv::Mat soil = measured[1].get<DepthImage>().mm(middle_half(truth.size()));
    std::size_t count = 0;
    const double distance = median_depth(soil, count);
    const double fraction = static_cast<double>(count) / static_cast<double>(soil.total());
    outcome.iou = std::min(outcome.iou, iou);
    outcome.soil_fraction = std::min(outcome.soil_fraction, fraction);
    if (count > 0) {
      outcome.error_mm = std::max(outcome.error_mm, std::abs(distance - *frame.truth->distance_mm));
    }
  }
  std::cout << "  " << name << ": IoU " << outcome.iou << ", |error| " << outcome.error_mm
            << " mm, soil " << outcome.soil_fraction << "\n";
  return outcome;
}

Outcome color_index(const std::vector<RegisteredFrame>& frames) {
  return evaluate("color_index", describe_color_index(), json::object(), frames);
}
Outcome lab_clusters(const std::vector<RegisteredFrame>& frames) {
  return evaluate("lab_clusters", describe_lab_clusters(), json::object(), frames);
}
Outcome depth_aided(const std::vector<RegisteredFrame>& frames) {
  return evaluate("depth_aided", describe_depth_aided(), json::object(), frames);
}
Outcome fusion(const std::vector<RegisteredFrame>& frames) {
  return evaluate("fusion", describe_fusion(), json::object(), frames);
}

// Below this fraction of soil in the region of interest estimation.ground_distance
// reports no valid measurement (its min_soil_fraction).
constexpr double kMinSoilFraction = 0.05;

// Paper case C: 150 dry straws and stubble. Every variant finds the straw (IoU 0.95-0.97
// measured; 0.92 for the depth-only variant, which misses the low flanks of round straws)
// and the distance within 0.04 mm: the bound of 0.15 mm leaves room for noise and is
// still a fifth of what wet straw costs a colour-only variant (below).
TEST(SimulatedCaseC, EveryVariantFindsTheStrawAndTheDistance) {
  const auto frames = simulated_frames("case_c", 1, kFrames);
  for (const Outcome& outcome : {color_index(frames), lab_clusters(frames), fusion(frames)}) {
    EXPECT_GT(outcome.iou, 0.93);
    EXPECT_LT(outcome.error_mm, 0.15);
    EXPECT_GT(outcome.soil_fraction, 0.4);
  }
  const Outcome by_depth = depth_aided(frames);
  EXPECT_GT(by_depth.iou, 0.9);
  EXPECT_LT(by_depth.error_mm, 0.15);

  // The classifier, trained on frames of another seed (other straws, other noise).
  train_segmenter::TrainingSet training(FeatureSet::kTexture);
  for (const RegisteredFrame& frame : simulated_frames("case_c", 2, kFrames)) {
    training.sample(frame, 2000, frame.frame_id + 1);
  }
  testing::TempDir temp;
  const auto model = temp.path() / "case_c.yml.gz";
  write_classifier_model(model, training.train({ClassifierKind::kForest, 30, 12}, "case_c seed 2"));
  const Outcome learnt = evaluate("pixel_classifier", describe_pixel_classifier(),
                                  {{"model", model.string()}}, frames);
  EXPECT_GT(learnt.iou, 0.94);
  EXPECT_LT(learnt.error_mm, 0.15);
}

// 150 dark, wet straws whose colour is the soil's: colour alone takes them for soil
// (IoU 0.05) and their tops pull the distance 0.73 mm short; their height gives them away
// (IoU 0.92-0.93, error 0.04 mm).
TEST(SimulatedWetStraw, HeightFindsWhatColourMisses) {
  const auto frames = simulated_frames("wet_straw", 1, kFrames);
  const Outcome by_colour = color_index(frames);
  EXPECT_LT(by_colour.iou, 0.2);
  EXPECT_GT(by_colour.error_mm, 0.5);
  for (const Outcome& outcome : {depth_aided(frames), fusion(frames)}) {
    EXPECT_GT(outcome.iou, 0.9);
    EXPECT_LT(outcome.error_mm, 0.15);
  }
}

// 1000 wet straws piled up to 250 mm, under 2 % of the soil in view: colour calls two
// thirds of the soil-coloured pile soil and would measure it (171 mm short); height
// leaves under 1 % "soil", too little for a measurement, as it must.
TEST(SimulatedCoveredWet, NoMeasurementFromAPileOfSoilColouredStraw) {
  const auto frames = simulated_frames("covered_wet", 1, kFrames);
  EXPECT_GT(color_index(frames).soil_fraction, 0.5);
  for (const Outcome& outcome : {depth_aided(frames), fusion(frames)}) {
    EXPECT_LT(outcome.soil_fraction, kMinSoilFraction);
  }
}

// The chain's fusion (over the soil's envelope) on heavy cover of sun-bleached straw, pale
// and nearly grey: Otsu's threshold falls among the soil's own colours, and colour alone
// leaves 3.8 % of the region soil, too little to measure. Where the depth puts a pixel on
// the soil, colour's residue must lie beyond the colours there: 6.9 % is left (the truth:
// 12 %), and the distance is 0.48 mm off (1 mm allowed: heavy cover's straw stands close
// around the soil, whose depth multipath lengthens).
TEST(SimulatedBleachedCover, ColourBarelyOffTheSoilsIsNotResidueWhereTheDepthSaysSoil) {
  const auto frames = simulated_frames("bleached_cover", 1, kFrames);
  const json chain = {{"envelope_px", 40}};
  json colour_alone = chain;
  colour_alone["soil_color_sigmas"] = 0;
  const Outcome before = evaluate("fusion, Otsu alone", describe_fusion(), colour_alone, frames);
  const Outcome after = evaluate("fusion", describe_fusion(), chain, frames);
  EXPECT_LT(before.soil_fraction, kMinSoilFraction);
  EXPECT_GT(after.soil_fraction, kMinSoilFraction);
  EXPECT_LT(after.error_mm, 1.0);
}

// The same on a pile of soil-coloured straw: the envelope puts the pile's lowest straws at
// the soil's level, the plane through the farthest depths does not, and too little is left
// to measure (3.8 %).
TEST(SimulatedCoveredWet, TheChainsFusionLeavesTooLittleSoilToMeasure) {
  const auto frames = simulated_frames("covered_wet", 1, kFrames);
  const Outcome outcome = evaluate("fusion", describe_fusion(), {{"envelope_px", 40}}, frames);
  EXPECT_LT(outcome.soil_fraction, kMinSoilFraction);
}

// A stage given the estimator's region of interest segments only it, and a little around
// it (for the edge pixels' dilation and smoothing): outside that area it is unknown, with no
// soil depth. Inside the region, the colour range's decisions are the whole image's; the
// variants that split the colours or fit the soil surface on what they see decide from
// the region alone and agree with the whole image on all but a few pixels (measured on
// case C: none differ for color_index, depth_aided and fusion, 77 of 76 800 for
// lab_clusters).
TEST(SimulatedCaseC, AStageGivenARegionSegmentsItAsInTheWholeImage) {
  const auto frames = simulated_frames("case_c", 1, 1);
  const RegisteredFrame& frame = frames.front();
  const cv::Size size = frame.truth->residue_mask.size();
  const cv::Rect roi = middle_half(size);
  const json region = {{"x", roi.x}, {"y", roi.y}, {"width", roi.width}, {"height", roi.height}};
  const cv::Rect area(roi.x - 8, roi.y - 8, roi.width + 16, roi.height + 16);
  const std::vector<std::pair<const char*, StageDescriptor>> stages = {
      {"color_threshold", describe_color_threshold()},
      {"color_index", describe_color_index()},
      {"lab_clusters", describe_lab_clusters()},
      {"depth_aided", describe_depth_aided()},
      {"fusion", describe_fusion()}};
  for (const auto& [name, stage] : stages) {
    SCOPED_TRACE(name);
    json params = {{"dilation_px", 2}};
    if (std::string(name) == "fusion") params["envelope_px"] = 40;
    testing::TransformHarness whole(stage, params);
    params["roi"] = region;
    testing::TransformHarness part(stage, params);
    const auto all = whole.run({frame.color, frame.depth}, frame.frame_id);
    const auto some = part.run({frame.color, frame.depth}, frame.frame_id);
    const cv::Mat& everywhere = all[0].get<ResidueMask>().values;
    const cv::Mat& in_part = some[0].get<ResidueMask>().values;
    const cv::Mat& soil = some[1].get<DepthImage>().mm;

    cv::Mat outside(size, CV_8UC1, cv::Scalar(255));
    outside(area).setTo(0);
    EXPECT_EQ(cv::countNonZero((in_part != ResidueMask::kUnknown) & outside), 0);
    EXPECT_EQ(cv::countNonZero((soil == soil) & outside), 0);  // NaN != NaN

    const int differ = cv::countNonZero(everywhere(roi) != in_part(roi));
    if (std::string(name) == "color_threshold") {
      EXPECT_EQ(differ, 0);
    } else {
      EXPECT_LT(differ, roi.area() / 100) << differ << " of " << roi.area() << " px differ";
    }
    std::cout << "  " << name << ": " << differ << " of " << roi.area() << " px differ\n";
  }
}

// Trained on one place and used on another: case C, wet straw and heavy cover (seed 2)
// for training, the rough field at another height (seed 1) to score. Wet straw has the
// soil's colour and heavy cover's lower straw is darker than soil, so a forest of the
// pixel's colour alone learns that soil colours can be residue and carries that to the
// field (IoU 0.81 measured); with the texture features (luminance over the image's median,
// local contrast, the straws' oriented gradients) it tells them by their shape (0.94). The
// margin asked, 0.08, is the measured 0.13 less room for another draw of the samples.
TEST(SimulatedField, TextureFeaturesCarryOverBetterThanColourAlone) {
  std::vector<RegisteredFrame> training_frames = simulated_frames("case_c", 2, kFrames);
  for (const char* preset : {"wet_straw", "heavy_cover"}) {
    for (auto& frame : simulated_frames(preset, 2, kFrames)) training_frames.push_back(frame);
  }
  const auto scored_frames = simulated_frames("field", 1, 1);
  auto iou = [&](FeatureSet set) {
    train_segmenter::TrainingSet training(set);
    for (const RegisteredFrame& frame : training_frames) {
      training.sample(frame, 2000, frame.frame_id + 1);
    }
    const ResidueClassifier classifier(training.train({ClassifierKind::kForest, 30, 12}, ""),
                                       kScoredEveryPx);
    train_segmenter::Scores scores;
    for (const RegisteredFrame& frame : scored_frames) {
      scores += *train_segmenter::score_frame(classifier, frame);
    }
    std::cout << "  " << feature_set_id(set) << ": IoU " << scores.residue_iou() << "\n";
    return scores.residue_iou();
  };
  const double colour = iou(FeatureSet::kColour);
  const double texture = iou(FeatureSet::kTexture);
  EXPECT_GT(texture, colour + 0.08);
}

}  // namespace
}  // namespace tilth::segmentation
