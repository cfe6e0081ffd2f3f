// Labels without hand work (tilth train-segmenter --labels depth) on the scene simulator,
// whose truth is known: the pixels depth labels agree with the truth mask and cover most
// of the frame, and a classifier trained on them, never shown a mask, segments a field's
// other frames about as well as one trained on the masks and far better than a colour
// rule. The bounds are the measured figures with a margin; the comments give the
// measurements (docs/segmentation-variants.md has the table).
#include <iostream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "label_tally.h"
#include "pixel_classifier/residue_classifier.h"
#include "segmenter_training.h"
#include "simulated_frames.h"
#include "soil_surface/depth_labels.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/testing/stage_harness.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

using train_segmenter::LabelTally;
using train_segmenter::RegisteredFrame;
using train_segmenter::Scores;

// tilth train-segmenter's defaults: soil within 1.5 mm, residue above 4 mm, a 1 px edge.
const DepthLabelOptions kDefaults{1.5, 4.0, 1, 0.0};

LabelTally tally(const DepthLabelOptions& options, const std::vector<RegisteredFrame>& frames) {
  const DepthLabels labeller(options);
  LabelTally total;
  cv::Mat labels;
  for (const RegisteredFrame& frame : frames) {
    labeller.label(frame.depth->mm, labels);
    total += train_segmenter::tally_labels(labels, frame);
  }
  return total;
}

// Measured (1 frame, seed 1): agreement 99.91 % (field: its 4 mm relief) to 99.98 %
// (case C; 99.2 % there without the 1 px edge: the straws' mixed edge pixels); coverage
// 59 % (tilted) to 88 % (heavy cover) of the pixels with trusted colour. Asked: 99.5 %
// (over five times the worst preset's share of errors) and 55 %.
TEST(DepthLabels, AgreeWithTheTruthWhereTheyLabelAndCoverMostPixels) {
  for (const char* preset :
       {"case_c", "low_sun", "heavy_cover", "shadows", "field", "tilted", "tall_stubble"}) {
    SCOPED_TRACE(preset);
    const LabelTally labelled = tally(kDefaults, simulated_frames(preset, 1, 1));
    std::cout << "  " << preset << ": agreement " << labelled.agreement() << ", coverage "
              << labelled.coverage() << " (soil " << double(labelled.soil) / labelled.pixels
              << ", residue " << double(labelled.residue) / labelled.pixels << ")\n";
    EXPECT_GE(labelled.agreement(), 0.995);
    EXPECT_GE(labelled.coverage(), 0.55);
    EXPECT_GT(labelled.soil, labelled.pixels / 20);
    EXPECT_GT(labelled.residue, labelled.pixels / 20);
    // Every labelled pixel the mask knows is judged: the mask's unknowns are its 1 px
    // boundaries, which the edge leaves unlabelled too (measured: 0.2 % of the labels).
    EXPECT_GT(labelled.judged, labelled.labelled() * 99 / 100);
  }
}

// Ridges 20 mm high: a plane through the farthest depths lies in the furrows and labels
// the ridges residue (agreement 49 % measured); the envelope over 40 px follows the
// ground (99.97 %). docs/segmentation-variants.md says to pass --envelope-px there.
TEST(DepthLabels, RidgesNeedTheEnvelope) {
  const auto frames = simulated_frames("ridges", 1, 2);
  EXPECT_LT(tally(kDefaults, frames).agreement(), 0.6);
  DepthLabelOptions envelope = kDefaults;
  envelope.envelope_px = 40;
  EXPECT_GE(tally(envelope, frames).agreement(), 0.995);
}

TEST(DepthLabels, MarginsLeaveABandBetweenTheClasses) {
  try {
    DepthLabels({3.0, 3.0, 1, 0.0});
    FAIL() << "constructed";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "depth labels of soil within 3 mm, residue above 3 mm, edge 1 px, "
              "envelope 0 px (expected residue above the soil band: residue above > soil "
              "within)");
  }
}

// The residue IoU of a classifier trained on `training` (labelled by depth or by the
// masks) against the truth of `scored`.
double trained_iou(const std::vector<RegisteredFrame>& training,
                   const std::vector<RegisteredFrame>& scored, bool by_depth) {
  train_segmenter::TrainingSet samples(FeatureSet::kTexture);
  const DepthLabels labeller(kDefaults);
  cv::Mat labels;
  for (const RegisteredFrame& frame : training) {
    if (by_depth) {
      labeller.label(frame.depth->mm, labels);
      samples.sample(frame, labels, 2000, frame.frame_id + 1);
    } else {
      samples.sample(frame, 2000, frame.frame_id + 1);
    }
  }
  const ResidueClassifier classifier(samples.train({ClassifierKind::kForest, 5, 6}, ""),
                                     kScoredEveryPx);
  Scores scores;
  for (const RegisteredFrame& frame : scored) {
    scores += *train_segmenter::score_frame(classifier, frame);
  }
  return scores.residue_iou();
}

// segmentation.color_index's residue IoU, undilated, on the pixels a classifier is scored on.
double color_index_iou(const std::vector<RegisteredFrame>& frames) {
  testing::TransformHarness stage(describe_color_index(), {{"dilation_px", 0}});
  Scores scores;
  for (const RegisteredFrame& frame : frames) {
    const auto out = stage.run({frame.color, frame.depth}, frame.frame_id);
    const cv::Mat said = out[0].get<ResidueMask>().values == ResidueMask::kResidue;
    const cv::Mat trusted = frame.color->status == RegisteredColor::kValid;
    const cv::Mat& truth = frame.truth->residue_mask;
    const cv::Mat is = truth == ResidueMask::kResidue, soil = truth == ResidueMask::kSoil;
    scores.true_residue += cv::countNonZero(said & is & trusted);
    scores.missed_residue += cv::countNonZero(~said & is & trusted);
    scores.false_residue += cv::countNonZero(said & soil & trusted);
    scores.true_soil += cv::countNonZero(~said & soil & trusted);
  }
  return scores.residue_iou();
}

// A field's own unlabelled frames (seed 2) teach a classifier that segments its other
// frames (seed 1). Measured residue IoU, trained on depth labels / on the masks / the
// colour rule color_index (undilated, the whole frame):
//   case_c       0.985 / 0.986 / 0.957
//   wet_straw    0.831 / 0.823 / 0.053  (straw the soil's colour: only its height tells)
//   heavy_cover  0.973 / 0.948 / 0.725  (its dark under-layer)
//   field        0.984 / 0.987 / 0.957
// Asked: no more than 0.03 below the masks' model (at most 0.003 below measured; the two
// models differ by up to 0.025 either way, as another draw of the samples would move
// them), above the colour rule on every preset (by 0.028 at least measured) and by 0.2 on
// average (0.27 measured).
TEST(DepthLabels, TeachAlmostAsWellAsTheMasks) {
  double depth_sum = 0, colour_sum = 0;
  const std::vector<std::string> presets = {"case_c", "wet_straw", "heavy_cover", "field"};
  for (const std::string& preset : presets) {
    SCOPED_TRACE(preset);
    const auto training = simulated_frames(preset, 2, 2);
    const auto scored = simulated_frames(preset, 1, 2);
    const double by_depth = trained_iou(training, scored, true);
    const double by_masks = trained_iou(training, scored, false);
    const double by_colour = color_index_iou(scored);
    std::cout << "  " << preset << ": depth labels " << by_depth << ", masks " << by_masks
              << ", color_index " << by_colour << "\n";
    EXPECT_GT(by_depth, by_masks - 0.03);
    EXPECT_GT(by_depth, by_colour + 0.01);
    depth_sum += by_depth;
    colour_sum += by_colour;
  }
  EXPECT_GT(depth_sum / presets.size(), colour_sum / presets.size() + 0.2);
}

}  // namespace
}  // namespace tilth::segmentation
