// tilth train-segmenter's leave-one-recording-out: each recording is scored by a model
// that never saw it. Three painted recordings: in two, residue is bright straw on brown
// soil; in the third it is dark grey on near-white soil, colours of its own, darker and
// brighter than anything the other two show. A model that saw the third learns its
// colours and scores it well; one trained on the other two calls its bright soil residue
// and its dark residue soil. So the third recording's row is low exactly when nothing of
// it leaked.
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

#include "leave_one_out.h"
#include "painted_frame.h"
#include "pixel_classifier/residue_classifier.h"
#include "segmenter_training.h"

namespace tilth::segmentation {
namespace {

using train_segmenter::RegisteredFrame;
using train_segmenter::Scores;
using train_segmenter::TrainingSet;

const cv::Size kSize(64, 48);

// Left half residue, right half soil, with 3 DN of noise.
RegisteredFrame halves(const cv::Vec3b& residue, const cv::Vec3b& soil, int seed) {
  PaintedFrame painted(kSize, soil, 500.0f);
  painted.paint(cv::Rect(0, 0, kSize.width / 2, kSize.height), residue);
  cv::Mat noise(kSize, CV_16SC3), noisy;
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, 3.0);
  painted.color->bgr.convertTo(noisy, CV_16SC3);
  cv::Mat(noisy + noise).convertTo(painted.color->bgr, CV_8UC3);
  auto truth = std::make_shared<GroundTruth>();
  truth->residue_mask = cv::Mat(kSize, CV_8UC1, cv::Scalar(ResidueMask::kSoil));
  truth->residue_mask(cv::Rect(0, 0, kSize.width / 2, kSize.height)).setTo(ResidueMask::kResidue);
  truth->residue_mask(cv::Rect(kSize.width / 2 - 1, 0, 2, kSize.height))
      .setTo(ResidueMask::kUnknown);
  return {static_cast<std::uint64_t>(seed), painted.color, painted.depth, truth};
}

struct Recording {
  std::vector<RegisteredFrame> frames;
  TrainingSet samples{FeatureSet::kColour};
};

std::vector<Recording> recordings() {
  const std::vector<std::pair<cv::Vec3b, cv::Vec3b>> looks = {
      {{120, 190, 220}, {55, 80, 110}},  // bright straw on brown soil
      {{110, 180, 215}, {50, 75, 100}},  // the same, a little darker
      {{30, 35, 40}, {235, 240, 245}}};  // dark weathered residue on pale soil
  std::vector<Recording> all(looks.size());
  for (std::size_t i = 0; i < looks.size(); ++i) {
    for (int seed = 1; seed <= 2; ++seed) {
      all[i].frames.push_back(halves(looks[i].first, looks[i].second, seed + 10 * int(i)));
      all[i].samples.sample(all[i].frames.back(), 400, seed);
    }
  }
  return all;
}

Scores score(const ClassifierModel& model, const std::vector<RegisteredFrame>& frames) {
  const ResidueClassifier classifier(model, kScoredEveryPx);
  Scores scores;
  for (const RegisteredFrame& frame : frames)
    scores += *train_segmenter::score_frame(classifier, frame);
  return scores;
}

const train_segmenter::ClassifierOptions kOptions{ClassifierKind::kForest, 20, 8};

TEST(LeaveOneRecordingOut, ScoresEachRecordingByAModelThatNeverSawIt) {
  const std::vector<Recording> all = recordings();
  std::vector<TrainingSet> sets;
  for (const Recording& recording : all) sets.push_back(recording.samples);
  const std::vector<Scores> rows = train_segmenter::leave_one_recording_out(
      sets, kOptions, [&](std::size_t held_out, const ClassifierModel& model) {
        return score(model, all[held_out].frames);
      });
  ASSERT_EQ(rows.size(), all.size());
  for (const Scores& row : rows) std::cout << "  IoU " << row.residue_iou() << "\n";
  for (const Scores& row : rows) {
    EXPECT_EQ(row.pixels(), 2u * (kSize.area() - 2 * kSize.height));
    for (const double share : {row.residue_iou(), row.precision(), row.recall()}) {
      EXPECT_GE(share, 0.0);
      EXPECT_LE(share, 1.0);
    }
  }
  // The two alike recordings teach each other (measured 1.0 and 1.0).
  EXPECT_GT(rows[0].residue_iou(), 0.9);
  EXPECT_GT(rows[1].residue_iou(), 0.9);
  // The odd one: what the others teach is wrong for it (measured 0).
  EXPECT_LT(rows[2].residue_iou(), 0.2);

  // Had it leaked: a model that saw it scores it well (measured 1.0). So the row above
  // is near 0 only because the fold left it out.
  TrainingSet everything(FeatureSet::kColour);
  for (const TrainingSet& set : sets) everything.add(set);
  EXPECT_GT(score(everything.train(kOptions, ""), all[2].frames).residue_iou(), 0.9);

  // The row recomputed: a model trained on the first two alone gives the same counts.
  TrainingSet first_two(FeatureSet::kColour);
  first_two.add(sets[0]);
  first_two.add(sets[1]);
  const Scores again = score(first_two.train(kOptions, ""), all[2].frames);
  EXPECT_EQ(again.true_residue, rows[2].true_residue);
  EXPECT_EQ(again.false_residue, rows[2].false_residue);
  EXPECT_EQ(again.missed_residue, rows[2].missed_residue);
}

TEST(LeaveOneRecordingOut, NeedsTwoRecordings) {
  const std::vector<TrainingSet> one(1, TrainingSet(FeatureSet::kColour));
  EXPECT_THROW(train_segmenter::leave_one_recording_out(
                   one, kOptions, [](std::size_t, const ClassifierModel&) { return Scores{}; }),
               Error);
}

}  // namespace
}  // namespace tilth::segmentation
