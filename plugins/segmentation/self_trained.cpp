// segmentation.self_trained: residue as a random forest sees it that the stage trains, and
// keeps retraining, on the field in front of it, labelled by depth: residue standing
// clearly above the soil surface and soil lying on it label themselves (DepthLabels), and
// the forest learns their colour and texture, so that it also finds the residue depth
// cannot tell from the soil (lying flat, its flanks, its edges).
//
//   depth ──► depth labels (residue / soil / unknown) ──► before the first model: residue
//   every learn_every_frames-th frame: its labels' pixels (samples_per_frame per class) ──►
//   the window of the last frames_kept such frames ──► a forest (trees, depth, features)
//   ──► replaces the model
//   color ──► the model's features ──► trees ──► residue ──► despeckle ──► dilate ──►
//   mask, soil_depth
//
// Invariant: a frame's mask comes from the model trained before it (or its own depth
// labels' residue, until there is one); a frame is learnt only after its mask is made. A
// window with fewer than samples_per_frame samples of a class (one frame's worth) trains
// nothing: the model before it stays, and the log says so once per change.
//
// Threads: training takes a tenth of a second or more (about 0.3 s on a full default
// window; segmenting a frame 25 ms). With training "background" (the default) it runs on
// one thread the stage owns, fed one frame at a time: a learning frame that comes while
// that thread is still training is not learnt (counted, and logged when the run
// finishes), and a new model takes over at whatever frame it is ready. So which frames
// are learnt, and which model segments a frame, depend on how fast the machine trains:
// not deterministic. With training "inline" the frame is learnt on the graph's thread
// before the next frame, and the same frames give the same masks. Either way the stage
// keeps a model and counts frames: it is serial.
//
//   "segment": {"type": "segmentation.self_trained", "params": {"roi": "middle_half"}}
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>

#include <opencv2/core.hpp>

#include "pixel_classifier/residue_classifier.h"
#include "pixel_classifier/training_set.h"
#include "pixel_classifier/tree_ensemble.h"
#include "residue_output.h"
#include "soil_surface/depth_labels.h"
#include "soil_surface/soil_surface.h"
#include "tilth/plugin.h"
#include "variants.h"

namespace tilth::segmentation {
namespace {

// A frame to learn from: its registered colour in the segmented area, which of those
// pixels have trusted colour, and its depth labels. The images are its own or shared
// read-only (a pooled image is not written again while a header holds it).
struct LabelledFrame {
  std::uint64_t frame_id = 0;
  cv::Mat bgr, trusted, labels;
};

std::string frames_text(std::size_t count) {
  return std::to_string(count) + (count == 1 ? " frame" : " frames");
}

// The window of the frames learnt last and the forest trained on it. Used by one thread
// at a time: the stage's training thread, or the graph's with training "inline".
class WindowTrainer {
 public:
  WindowTrainer(const Params& params, Logger log)
      : features_(feature_set_named(params.string("features"))),
        options_{ClassifierKind::kForest, static_cast<int>(params.integer("trees")),
                 static_cast<int>(params.integer("depth")), 1},
        per_class_(static_cast<std::size_t>(params.integer("samples_per_frame"))),
        frames_kept_(static_cast<std::size_t>(params.integer("frames_kept"))),
        scored_every_px_(static_cast<int>(params.integer("scored_every_px"))),
        log_(std::move(log)) {}

  // Samples the frame into the window and trains a model on the window: empty when a
  // class has too few samples there or training fails (logged once per change, never
  // thrown).
  std::shared_ptr<const ResidueClassifier> learn(const LabelledFrame& frame) {
    try {
      TrainingSet samples(features_);
      samples.sample(frame.bgr, frame.trusted, frame.labels, per_class_, frame.frame_id + 1,
                     "frame " + std::to_string(frame.frame_id) + ": its depth labels");
      window_.push_back(std::move(samples));
      if (window_.size() > frames_kept_) window_.pop_front();
      TrainingSet all(features_);
      for (const TrainingSet& kept : window_) all.add(kept);
      if (all.soil() < per_class_ || all.residue() < per_class_) {
        report(State::kLacking, frame.frame_id,
               "the depth labels of the last " + frames_text(window_.size()) + " learnt give " +
                   std::to_string(all.soil()) + " soil and " + std::to_string(all.residue()) +
                   " residue samples (expected " + std::to_string(per_class_) +
                   " of each, samples_per_frame)");
        return nullptr;
      }
      auto model =
          std::make_shared<const ResidueClassifier>(all.train(options_, ""), scored_every_px_);
      report(State::kTrained, frame.frame_id,
             "trained on " + frames_text(window_.size()) + " (" + std::to_string(all.soil()) +
                 " soil, " + std::to_string(all.residue()) + " residue samples)");
      return model;
    } catch (const std::exception& error) {
      report(State::kFailed, frame.frame_id, std::string("training failed: ") + error.what());
      return nullptr;
    }
  }

 private:
  enum class State { kNone, kTrained, kLacking, kFailed };

  void report(State now, std::uint64_t frame_id, const std::string& what) {
    const State before = std::exchange(state_, now);
    if (now == before) return;
    const std::string where = "frame " + std::to_string(frame_id) + ": ";
    if (now == State::kTrained) {
      log_.info(where + (had_model_ ? "a model again, " : "first model, ") + what);
      had_model_ = true;
      return;
    }
    const std::string kept = had_model_ ? "; the previous model stays"
                                        : "; no model yet: the mask is the depth labels' residue";
    if (now == State::kLacking) log_.warning(where + what + kept);
    if (now == State::kFailed) log_.error(where + what + kept);
  }

  const FeatureSet features_;
  const ClassifierOptions options_;
  const std::size_t per_class_;
  const std::size_t frames_kept_;
  const int scored_every_px_;
  const Logger log_;
  std::deque<TrainingSet> window_;
  State state_ = State::kNone;
  bool had_model_ = false;
};

// Learns frames on a thread of its own, one at a time: a frame offered while another
// waits or is being learnt is turned away. Its destructor stops the thread and joins it,
// after the frame in hand, if any.
class TrainingThread {
 public:
  explicit TrainingThread(std::function<void(const LabelledFrame&)> learn)
      : learn_(std::move(learn)), thread_([this] { run(); }) {}

  ~TrainingThread() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }

  TrainingThread(const TrainingThread&) = delete;
  TrainingThread& operator=(const TrainingThread&) = delete;

  // False when the thread is busy: the frame is not learnt.
  bool offer(LabelledFrame frame) {
    {
      std::lock_guard lock(mutex_);
      if (pending_ || learning_) return false;
      pending_ = std::move(frame);
    }
    wake_.notify_one();
    return true;
  }

 private:
  void run() {
    std::unique_lock lock(mutex_);
    while (true) {
      wake_.wait(lock, [this] { return stopping_ || pending_; });
      if (stopping_) return;
      const LabelledFrame frame = std::move(*pending_);
      pending_.reset();
      learning_ = true;
      lock.unlock();
      learn_(frame);
      lock.lock();
      learning_ = false;
    }
  }

  const std::function<void(const LabelledFrame&)> learn_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<LabelledFrame> pending_;
  bool learning_ = false;
  bool stopping_ = false;
  std::thread thread_;  // last: starts once the rest exists
};

constexpr DepthLabelOptions kDepthLabelDefaults;

DepthLabelOptions depth_label_options(const Params& params) {
  return {params.number("soil_within_mm"), params.number("residue_above_mm"),
          static_cast<int>(params.integer("edge_px")), params.number("envelope_px")};
}

class SelfTrained final : public Transform {
 public:
  explicit SelfTrained(const StageContext& context)
      : labeller_(depth_label_options(context.params)),
        min_value_(static_cast<int>(context.params.integer("min_value"))),
        learn_every_(static_cast<std::uint64_t>(context.params.integer("learn_every_frames"))),
        output_(context.params),
        trainer_(context.params, context.log),
        log_(context.log) {
    if (context.params.string("training") == "background") {
      thread_.emplace([this](const LabelledFrame& frame) { learn(frame); });
    }
  }

  void process(Frame& frame) override {
    const ResidueInputs in = read_residue_inputs(frame, min_value_, output_.area(frame));
    thread_local cv::Mat trusted, residue;
    cv::bitwise_not(in.untrusted, trusted);
    const std::shared_ptr<const ResidueClassifier> model = current_model();
    const bool learning = frames_++ % learn_every_ == 0;
    cv::Mat labels;  // its own when learnt: the training thread may keep it
    if (!model || learning) labeller_.label(in.depth_mm, labels);
    if (model) {
      model->classify(frame.input<RegisteredColor>(kColorInput).bgr, in.area, trusted, residue);
    } else {
      cv::compare(labels, ResidueMask::kResidue, residue, cv::CMP_EQ);
    }
    output_.emit(frame, in.area, residue, in.untrusted, in.unknown, in.depth_mm);
    if (!learning) return;

    LabelledFrame learnt{frame.info().frame_id, in.bgr, trusted.clone(), labels};
    if (!thread_) {
      learn(learnt);
    } else if (!thread_->offer(std::move(learnt))) {
      std::lock_guard lock(mutex_);
      ++turned_away_;
    }
  }

  void finish() override {
    std::lock_guard lock(mutex_);
    log_.info(std::to_string(learnt_) + " frames learnt, " + std::to_string(models_) +
              " models trained; " + std::to_string(turned_away_) +
              " frames to learn came while training and were not learnt");
  }

 private:
  std::shared_ptr<const ResidueClassifier> current_model() const {
    std::lock_guard lock(mutex_);
    return model_;
  }

  void learn(const LabelledFrame& frame) {
    std::shared_ptr<const ResidueClassifier> model = trainer_.learn(frame);
    std::lock_guard lock(mutex_);
    ++learnt_;
    if (!model) return;
    ++models_;
    model_ = std::move(model);
  }

  const DepthLabels labeller_;
  const int min_value_;
  const std::uint64_t learn_every_;
  ResidueOutput output_;
  WindowTrainer trainer_;  // the training thread's, or the graph's inline
  const Logger log_;
  std::uint64_t frames_ = 0;
  mutable std::mutex mutex_;
  std::shared_ptr<const ResidueClassifier> model_;           // guarded by mutex_
  std::uint64_t learnt_ = 0, models_ = 0, turned_away_ = 0;  // guarded by mutex_
  std::optional<TrainingThread> thread_;  // last: stopped before what it uses goes
};

}  // namespace

StageDescriptor describe_self_trained() {
  StageDescriptor d;
  d.type = "segmentation.self_trained";
  d.summary =
      "residue mask from a random forest the stage keeps training on the field's own depth "
      "labels (no model file)";
  d.inputs = residue_inputs();
  d.outputs = residue_outputs();
  d.params = {
      ParamSpec::choice("training", {"background", "inline"}, "background")
          .describe("background: trained on a thread of the stage's own, a frame to learn "
                    "that comes while it trains is not learnt (not deterministic); inline: "
                    "on the graph's thread before the next frame (deterministic, slower)"),
      ParamSpec::integer("learn_every_frames", 10)
          .range(1, 100'000)
          .describe("every n-th frame (the first, then every n-th) is learnt"),
      ParamSpec::integer("frames_kept", 20)
          .range(1, 1000)
          .describe("the model is trained on the samples of the last n frames learnt"),
      ParamSpec::integer("samples_per_frame", 300)
          .range(10, 100'000)
          .describe("pixels drawn per class from a learnt frame's depth labels; a window "
                    "with fewer of a class trains nothing"),
      ParamSpec::choice("features", {"colour", "texture"}, "texture")
          .describe("the pixel features the forest sees (docs/segmentation-variants.md)"),
      ParamSpec::integer("trees", 8).range(1, 200).describe("trees of the random forest"),
      ParamSpec::integer("depth", 8)
          .range(1, TreeEnsemble::kMaxDepth)
          .describe("deepest level of a tree"),
      ParamSpec::number("soil_within_mm", kDepthLabelDefaults.soil_within_mm)
          .range(0.1, 50)
          .in_unit("mm")
          .describe("depth labels: soil lies within this of the fitted soil surface"),
      ParamSpec::number("residue_above_mm", kDepthLabelDefaults.residue_above_mm)
          .range(0.2, 500)
          .in_unit("mm")
          .describe("depth labels: residue stands more than this above it (more than "
                    "soil_within_mm: the band between is not labelled)"),
      ParamSpec::integer("edge_px", kDepthLabelDefaults.edge_px)
          .range(0, 20)
          .in_unit("px")
          .describe("depth labels: no label within this of the other class or the band"),
      envelope_px_param(),
      scored_every_px_param(),
      dilation_px_param(),
      segmented_roi_param(),
      speckle_px_param(1),
      min_value_param(),
  };
  d.concurrency = Concurrency::kSerial;
  d.create = factory<SelfTrained>();
  return d;
}

TILTH_STAGE(describe_self_trained());

}  // namespace tilth::segmentation
