// segmentation.self_trained on passes of the scene simulator, whose truth is known: a field
// seen as 4 scenes of 10 frames each (seeds 1-4, as a machine driving on sees new ground),
// the stage learning from nothing but the frames' depth. The bounds are the measured
// figures with a margin; the comments give the measurements (docs/segmentation-variants.md
// has the table). The background training runs on small painted frames, quick enough for
// ThreadSanitizer.
#include <chrono>
#include <iostream>
#include <mutex>
#include <optional>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "painted_frame.h"
#include "simulated_frames.h"
#include "soil_surface/depth_labels.h"
#include "tilth/error.h"
#include "tilth/log.h"
#include "tilth/messages/residue_mask.h"
#include "tilth/testing/stage_harness.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

using nlohmann::json;
using train_segmenter::RegisteredFrame;

constexpr int kScenes = 4;
constexpr int kFramesPerScene = 10;

// The stage's default depth-label margins.
const DepthLabelOptions kLabelOptions{1.5, 4.0, 1, 0.0};

// A pass over a preset's field: kScenes scenes (seeds 1...) of kFramesPerScene frames.
std::vector<RegisteredFrame> pass(const std::string& preset) {
  std::vector<RegisteredFrame> frames;
  for (int seed = 1; seed <= kScenes; ++seed) {
    for (auto& frame : simulated_frames(preset, seed, kFramesPerScene)) {
      frames.push_back(std::move(frame));
    }
  }
  return frames;
}

// Log lines, from any thread, to see what the stage says.
class CapturedLog {
 public:
  CapturedLog() {
    previous_ = set_log_handler([this](LogLevel, std::string_view, std::string_view message) {
      std::lock_guard lock(mutex_);
      text_ += std::string(message) + "\n";
    });
  }
  ~CapturedLog() { set_log_handler(previous_); }
  std::string text() const {
    std::lock_guard lock(mutex_);
    return text_;
  }

 private:
  LogHandler previous_;
  mutable std::mutex mutex_;
  std::string text_;
};

int occurrences(const std::string& text, const std::string& part) {
  int count = 0;
  for (auto at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

// Pixel counts of a residue decision against the truth, on the pixels both judge.
struct Counts {
  double both = 0, either = 0, hidden = 0, hidden_found = 0;
  double labels_both = 0, labels_either = 0;
  double iou() const { return either == 0 ? 1.0 : both / either; }
  // Of the true residue pixels the frame's depth labels do not call residue.
  double hidden_recall() const { return hidden == 0 ? 0.0 : hidden_found / hidden; }
  // The depth labels' residue as the mask, on the same pixels.
  double labels_iou() const { return labels_either == 0 ? 1.0 : labels_both / labels_either; }
};

// The masks (undilated) of `stage` on frames [from, end) of a pass run through it from the
// first, against the truth.
Counts score(const StageDescriptor& stage, const json& params,
             const std::vector<RegisteredFrame>& frames, std::size_t from) {
  json undilated = params;
  undilated["dilation_px"] = 0;
  testing::TransformHarness harness(stage, undilated);
  const DepthLabels labeller(kLabelOptions);
  Counts counts;
  cv::Mat labels;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const RegisteredFrame& frame = frames[i];
    const auto out = harness.run({frame.color, frame.depth}, i);
    if (i < from) continue;
    const cv::Mat& mask = out[0].get<ResidueMask>().values;
    const cv::Mat& truth = frame.truth->residue_mask;
    const cv::Mat judged = (truth != ResidueMask::kUnknown) & (mask != ResidueMask::kUnknown);
    const cv::Mat said = (mask == ResidueMask::kResidue) & judged;
    const cv::Mat is = (truth == ResidueMask::kResidue) & judged;
    counts.both += cv::countNonZero(said & is);
    counts.either += cv::countNonZero(said | is);
    labeller.label(frame.depth->mm, labels);
    const cv::Mat hidden = is & (labels != ResidueMask::kResidue);
    counts.hidden += cv::countNonZero(hidden);
    counts.hidden_found += cv::countNonZero(hidden & said);
    const cv::Mat labelled = (labels == ResidueMask::kResidue) & judged;
    counts.labels_both += cv::countNonZero(labelled & is);
    counts.labels_either += cv::countNonZero(labelled | is);
  }
  return counts;
}

// Learns every 5th frame (twice per scene) from the last 8 learnt, on the graph's thread.
const json kInline = {{"training", "inline"}, {"learn_every_frames", 5}, {"frames_kept", 8}};

// A model trained on each scene's first frame (and those before) segments the rest, and
// the next scene's first 5 frames before it learns that scene. Measured over scenes 2-4
// (the first is warm-up), residue IoU self_trained / color_index / the depth labels'
// residue alone, and the recall of self_trained on the true residue the frame's own depth
// labels do not call residue (soil or unlabelled: the straws' flanks and edges, straw
// lying low):
//   wet_straw    0.839 / 0.051 / 0.632, recall 0.81 of 856 000 px
//   heavy_cover  0.956 / 0.808 / 0.934, recall 0.84 of 429 000 px
// Asked: IoU 0.80 and 0.92 (0.04 below measured: twice the 0.01-0.02 that other forest
// sizes, sample counts and feature sets moved it), above color_index by 0.5 and 0.1 and
// above the depth labels by 0.15 and 0.01, and a recall of 0.7.
TEST(SelfTrained, LearnsWhatColourRulesAndDepthLabelsMiss) {
  struct Expected {
    const char* preset;
    double iou, over_colour, over_labels;
  };
  for (const Expected& expected :
       {Expected{"wet_straw", 0.80, 0.5, 0.15}, Expected{"heavy_cover", 0.92, 0.1, 0.01}}) {
    SCOPED_TRACE(expected.preset);
    const auto frames = pass(expected.preset);
    const Counts learnt = score(describe_self_trained(), kInline, frames, kFramesPerScene);
    const Counts colour = score(describe_color_index(), json::object(), frames, kFramesPerScene);
    std::cout << "  " << expected.preset << ": self_trained IoU " << learnt.iou() << ", recall "
              << learnt.hidden_recall() << " of the " << learnt.hidden
              << " residue px depth does not label; color_index IoU " << colour.iou()
              << ", the depth labels' residue " << learnt.labels_iou() << "\n";
    EXPECT_GT(learnt.iou(), expected.iou);
    EXPECT_GT(learnt.iou(), colour.iou() + expected.over_colour);
    EXPECT_GT(learnt.iou(), learnt.labels_iou() + expected.over_labels);
    EXPECT_GT(learnt.hidden_recall(), 0.7);
  }
}

bool same_residue(const cv::Mat& mask, const cv::Mat& labels) {
  const cv::Mat known = mask != ResidueMask::kUnknown;
  const cv::Mat said = mask == ResidueMask::kResidue, labelled = labels == ResidueMask::kResidue;
  return cv::countNonZero((said != labelled) & known) == 0;
}

// The counts the stage logs when the stream ends: frames learnt, models trained, frames
// turned away while the training thread was busy.
struct FinishCounts {
  std::string line;
  int learnt = 0, models = 0, turned_away = 0;
};

std::optional<FinishCounts> finish_counts(const std::string& log) {
  static const std::regex kCounts(
      "(\\d+) frames learnt, (\\d+) models trained; (\\d+) frames to learn came while "
      "training and were not learnt");
  std::smatch found;
  if (!std::regex_search(log, found, kCounts)) return std::nullopt;
  return FinishCounts{found[0], std::stoi(found[1]), std::stoi(found[2]), std::stoi(found[3])};
}

// Undilated and not despeckled, so that the mask is the decision itself.
const json kBare = {{"dilation_px", 0}, {"speckle_px", 0}};

// Frame 0 is segmented before anything is learnt: by its depth labels' residue, wherever
// its colour and depth are known. Frame 1 has the model learnt from frame 0.
TEST(SelfTrained, BeforeItsFirstModelTheMaskIsTheDepthLabelsResidue) {
  const auto frames = simulated_frames("wet_straw", 1, 2);
  json params = kInline;
  params.update(kBare);
  testing::TransformHarness stage(describe_self_trained(), params);
  const DepthLabels labeller(kLabelOptions);
  cv::Mat labels;
  for (std::size_t i = 0; i < 2; ++i) {
    const auto out = stage.run({frames[i].color, frames[i].depth}, i);
    labeller.label(frames[i].depth->mm, labels);
    EXPECT_EQ(same_residue(out[0].get<ResidueMask>().values, labels), i == 0) << "frame " << i;
  }
}

// Soil at 500 mm with straw lying across it: two straws 10 mm high, which depth labels
// residue, and one of the same colour lying flat in the soil, which it labels soil.
PaintedFrame straw_on_soil(int seed) {
  PaintedFrame frame({160, 120}, {60, 80, 110}, 500.0f);
  cv::Mat noise(frame.depth->mm.size(), CV_32FC1);
  cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, 0.3);
  frame.depth->mm += noise;
  const cv::Vec3b straw{120, 200, 220};
  frame.paint({20, 0, 12, 120}, straw, 490.0f);
  frame.paint({70, 0, 12, 120}, straw, 490.0f);
  frame.paint({120, 0, 12, 120}, straw);
  return frame;
}
const cv::Rect kFlatStraw(122, 2, 8, 116);  // the flat straw, 2 px in from its edges

// In the background the first model comes while frames go on, and the first frame after
// it is segmented by it: it finds the flat straw depth calls soil, in every frame after,
// whichever model does. The stage is destroyed while it learns.
TEST(SelfTrained, TrainsInTheBackground) {
  const CapturedLog log;
  json params = {{"learn_every_frames", 1}, {"samples_per_frame", 100}};
  params.update(kBare);
  testing::TransformHarness stage(describe_self_trained(), params);
  auto flat_straw_found = [&](int i) {
    const PaintedFrame frame = straw_on_soil(i);
    const auto out = stage.run({frame.color, frame.depth}, i);
    const cv::Mat& mask = out[0].get<ResidueMask>().values;
    return cv::countNonZero(mask(kFlatStraw) == ResidueMask::kResidue);
  };
  EXPECT_EQ(flat_straw_found(0), 0);
  // Training takes milliseconds here; a minute leaves room for a loaded machine and for
  // ThreadSanitizer.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (log.text().find("first model") == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_NE(log.text().find("frame 0: first model, trained on 1 frame ("), std::string::npos)
      << log.text();
  // Each frame is offered to the training thread, which takes it or is still busy: models
  // are swapped while frames are segmented.
  for (int i = 1; i < 30; ++i) EXPECT_EQ(flat_straw_found(i), kFlatStraw.area()) << "frame " << i;
  // Every frame was learnt or turned away, but for the one the thread may still hold.
  stage.finish();
  const auto counts = finish_counts(log.text());
  ASSERT_TRUE(counts) << log.text();
  EXPECT_GE(counts->models, 1);
  EXPECT_LE(counts->models, counts->learnt);
  EXPECT_GE(counts->learnt + counts->turned_away, 29);
  EXPECT_LE(counts->learnt + counts->turned_away, 30);
}

// Bare soil: the depth labels find no residue, so nothing is trained, the log says so once
// however many frames are learnt, and the mask stays the labels' (no residue).
TEST(SelfTrained, AWindowWithoutResidueTrainsNothingAndSaysSoOnce) {
  const auto frames = simulated_frames("flat", 1, 6);
  const CapturedLog log;
  json params = {{"training", "inline"}, {"learn_every_frames", 1}};
  params.update(kBare);
  testing::TransformHarness stage(describe_self_trained(), params);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto out = stage.run({frames[i].color, frames[i].depth}, i);
    EXPECT_EQ(cv::countNonZero(out[0].get<ResidueMask>().values == ResidueMask::kResidue), 0);
  }
  EXPECT_EQ(occurrences(log.text(), "residue samples (expected 300 of each"), 1) << log.text();
  EXPECT_NE(log.text().find("no model yet: the mask is the depth labels' residue"),
            std::string::npos);
  EXPECT_EQ(log.text().find("model,"), std::string::npos) << log.text();
  stage.finish();
  const auto counts = finish_counts(log.text());
  ASSERT_TRUE(counts) << log.text();
  EXPECT_EQ(counts->line,
            "6 frames learnt, 0 models trained; 0 frames to learn came while "
            "training and were not learnt");
}

TEST(SelfTrained, RefusesMarginsWithoutABandBetweenSoilAndResidue) {
  try {
    testing::TransformHarness stage(describe_self_trained(),
                                    {{"soil_within_mm", 3.0}, {"residue_above_mm", 3.0}});
    FAIL() << "constructed";
  } catch (const Error& error) {
    EXPECT_EQ(std::string(error.what()),
              "depth labels of soil within 3 mm, residue above 3 mm, edge 1 px, envelope 0 px "
              "(expected residue above the soil band: residue above > soil within)");
  }
}

}  // namespace
}  // namespace tilth::segmentation
