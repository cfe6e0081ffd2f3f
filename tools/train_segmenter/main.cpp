// `tilth train-segmenter` (the tilth-train-segmenter program): trains the classifier of
// segmentation.pixel_classifier from recordings with ground-truth masks, reports how well
// it does where it was not trained (other recordings, or held-out frames), and writes the
// model file.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "command_line.h"
#include "commands.h"
#include "framework/graph_session.h"
#include "leave_one_out.h"
#include "pixel_classifier/classifier_model.h"
#include "segmenter_training.h"
#include "tilth/error.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;
using tilth::segmentation::ClassifierModel;
using tilth::segmentation::FeatureSet;
using tilth::segmentation::ResidueClassifier;
using tilth::train_segmenter::ClassifierOptions;
using tilth::train_segmenter::RegisteredFrame;
using tilth::train_segmenter::RegisteredFrames;
using tilth::train_segmenter::Scores;
using tilth::train_segmenter::TrainingSet;

constexpr const char* kUsage =
    R"(usage: tilth train-segmenter RECORDING... --out MODEL [OPTIONS]

Trains the pixel classifier of segmentation.pixel_classifier (a random forest or boosted
trees over each pixel's colour and texture features) on recordings with ground-truth
residue masks, scores it where it was not trained, and writes MODEL (OpenCV YAML;
.yml.gz compresses it).

Each RECORDING is an image-folder recording (a folder) or an MCAP file. Frames go
through depth projection and registration as in graphs/measurement-chain.json, so the
classifier sees the colours the stage will see; frames without a mask are skipped.

Scoring: with --test, on those recordings; else, with several RECORDINGs, leave one
recording out (each scored by a model trained on the others); with one, on every 5th
frame, held out. IoU, precision and recall of residue per recording and overall (pixels
pooled); MODEL is then trained on every RECORDING.

  --calibration FILE   a rig calibration overriding the one each recording carries
                       (a warning names what differs; default: each recording's own)
  --out MODEL          the model file to write (required)
  --test RECORDING     score on this recording instead (repeatable)
  --features SET       texture (default): colour, luminance and its texture at 3
                       scales; colour: the pixel's colour alone
  --classifier KIND    forest (default, cv::ml::RTrees) or boosted (cv::ml::Boost)
  --samples N          pixels drawn per frame and class (default 2000)
  --seed N             seed of the draw (default 1): the same inputs and seed give the
                       same model
  --trees N            trees (default 5 for a forest, 50 boosted)
  --depth N            deepest tree level, at most 16 (default 6 for a forest, 3
                       boosted)
  --scored-every N     score as the stage with scored_every_px N does (default 2: every
                       2nd pixel of every 2nd row, and between them where they disagree)
  --report FILE        the scores as JSON as well
)";

constexpr std::uint64_t kHoldOutEvery = 5;

int usage_error(const std::string& message) {
  std::cerr << "tilth train-segmenter: " << message << "\n\n" << kUsage;
  return kExitUsage;
}

// The source stage that reads a recording: a folder is an image-folder recording.
RegisteredFrames open_recording(const tilth::StageRegistry& registry, const fs::path& recording,
                                const fs::path& calibration) {
  std::error_code error;
  if (!fs::exists(recording, error)) {
    throw tilth::Error("recording '" + recording.string() +
                       "' does not exist (expected an image-folder recording or an MCAP file)");
  }
  const bool folder = fs::is_directory(recording, error);
  return RegisteredFrames(registry, folder ? "recording.image_folder" : "mcap.player",
                          {{"path", recording.string()}}, calibration);
}

std::string number(const char* format, double value) {
  char text[32];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

std::string scores_text(const Scores& scores) {
  return "accuracy " + number("%.2f %%", 100 * scores.accuracy()) + ", residue IoU " +
         number("%.2f %%", 100 * scores.residue_iou()) + ", precision " +
         number("%.2f %%", 100 * scores.precision()) + ", recall " +
         number("%.2f %%", 100 * scores.recall()) + " over " + std::to_string(scores.pixels()) +
         " pixels";
}

struct Row {
  std::string recording;
  Scores scores;
  std::vector<std::string> trained_on;
};

nlohmann::json scores_json(const Scores& scores) {
  return {{"iou", scores.residue_iou()},
          {"precision", scores.precision()},
          {"recall", scores.recall()},
          {"accuracy", scores.accuracy()},
          {"pixels", scores.pixels()},
          {"true_residue", scores.true_residue},
          {"false_residue", scores.false_residue},
          {"missed_residue", scores.missed_residue},
          {"true_soil", scores.true_soil}};
}

// The table of rows and the pooled overall; returns the pooled scores.
Scores print_rows(const std::string& scoring, const std::vector<Row>& rows) {
  std::size_t width = 7;
  for (const Row& row : rows) width = std::max(width, row.recording.size());
  auto line = [&](const std::string& name, const Scores& scores) {
    std::cout << "  " << name << std::string(width - name.size() + 2, ' ')
              << number("%5.3f", scores.residue_iou()) << "  "
              << number("%9.3f", scores.precision()) << "  " << number("%6.3f", scores.recall())
              << "  " << number("%8.3f", scores.accuracy()) << "  " << scores.pixels() << "\n";
  };
  std::cout << scoring << ":\n  recording" << std::string(width - 7, ' ')
            << "IoU  precision  recall  accuracy  pixels\n";
  Scores overall;
  double iou_sum = 0;
  for (const Row& row : rows) {
    line(row.recording, row.scores);
    overall += row.scores;
    iou_sum += row.scores.residue_iou();
  }
  line("overall", overall);
  std::cout << "  mean IoU of the recordings: "
            << number("%.3f", iou_sum / static_cast<double>(rows.size())) << "\n";
  return overall;
}

void write_report(const fs::path& file, const std::string& scoring, const std::vector<Row>& rows,
                  const Scores& overall, const nlohmann::json& settings) {
  nlohmann::json report = settings;
  report["scoring"] = scoring;
  report["recordings"] = nlohmann::json::array();
  double iou_sum = 0;
  for (const Row& row : rows) {
    nlohmann::json entry = scores_json(row.scores);
    entry["recording"] = row.recording;
    entry["trained_on"] = row.trained_on;
    report["recordings"].push_back(entry);
    iou_sum += row.scores.residue_iou();
  }
  report["overall"] = scores_json(overall);
  report["mean_iou"] = iou_sum / static_cast<double>(rows.size());
  std::ofstream out(file);
  out << report.dump(2) << "\n";
  if (!out) throw tilth::Error("report '" + file.string() + "' cannot be written");
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1,
                   std::set<std::string>{"--calibration", "--out", "--test", "--samples", "--seed",
                                         "--trees", "--depth", "--features", "--classifier",
                                         "--report", "--scored-every"},
                   std::set<std::string>{"--help"});
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const CommandLine& line = *parsed;
  if (line.flag("--help")) {
    std::cout << kUsage;
    return kExitOk;
  }
  if (line.positional().empty()) return usage_error("expected at least one RECORDING");
  if (!line.value("--out")) return usage_error("--out MODEL is required");
  std::uint64_t samples = 0, seed = 0;
  int scored_every_px = tilth::segmentation::kScoredEveryPx;
  ClassifierOptions options;
  FeatureSet features = FeatureSet::kTexture;
  try {
    features = tilth::segmentation::feature_set_named(line.value("--features").value_or("texture"));
    options.kind =
        tilth::segmentation::classifier_kind_named(line.value("--classifier").value_or("forest"));
    const bool forest = options.kind == tilth::segmentation::ClassifierKind::kForest;
    // A frame has 300 000 pixels; the stage holds trees of up to 16 levels
    // (TreeEnsemble::kMaxDepth); 10 000 trees take hours to train.
    samples = line.count("--samples", 1, 1'000'000).value_or(2000);
    seed = line.count("--seed", 1, std::numeric_limits<std::uint32_t>::max()).value_or(1);
    options.seed = seed;
    options.trees = static_cast<int>(line.count("--trees", 1, 10'000).value_or(forest ? 5 : 50));
    options.depth =
        static_cast<int>(line.count("--depth", 1, tilth::segmentation::TreeEnsemble::kMaxDepth)
                             .value_or(forest ? 6 : 3));
    scored_every_px =
        static_cast<int>(line.count("--scored-every", 1, tilth::segmentation::kMaxScoredEveryPx)
                             .value_or(scored_every_px));
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const fs::path calibration = line.value("--calibration").value_or("");
  const fs::path out = *line.value("--out");
  const std::vector<std::string> tests = line.values("--test");
  const std::vector<std::string>& recordings = line.positional();
  const bool hold_out_frames = tests.empty() && recordings.size() == 1;

  try {
    const auto registry = tilth::load_plugins(".");
    std::vector<TrainingSet> sets;
    std::vector<RegisteredFrame> held_out;
    std::uint64_t draw = 0;
    for (const std::string& recording : recordings) {
      sets.emplace_back(features);
      RegisteredFrames frames = open_recording(*registry, recording, calibration);
      std::uint64_t used = 0, kept_out = 0, unlabelled = 0, position = 0;
      while (auto frame = frames.next()) {
        if (frame->truth->residue_mask.empty()) {
          ++unlabelled;
        } else if (hold_out_frames && position++ % kHoldOutEvery == kHoldOutEvery - 1) {
          held_out.push_back(std::move(*frame));
          ++kept_out;
        } else {
          sets.back().sample(*frame, static_cast<std::size_t>(samples), seed * 1'000'003 + draw++);
          ++used;
        }
      }
      std::cout << recording << ": " << used << " frames for training, " << kept_out
                << " held out, " << unlabelled << " without a mask\n";
    }
    auto score_recording = [&](const std::string& recording, const ClassifierModel& model) {
      const ResidueClassifier classifier(model, scored_every_px);
      RegisteredFrames frames = open_recording(*registry, recording, calibration);
      Scores scores;
      while (const auto frame = frames.next()) {
        if (const auto scored = tilth::train_segmenter::score_frame(classifier, *frame)) {
          scores += *scored;
        }
      }
      return scores;
    };

    std::string sources;
    TrainingSet all(features);
    for (std::size_t i = 0; i < sets.size(); ++i) {
      all.add(sets[i]);
      sources += (sources.empty() ? "" : ", ") + recordings[i];
    }
    const std::string settings_text =
        std::string(tilth::segmentation::feature_set_id(features)) + " features, " +
        std::to_string(options.trees) + " " +
        (options.kind == tilth::segmentation::ClassifierKind::kForest ? "trees" : "boosted trees") +
        " of depth <= " + std::to_string(options.depth) + ", seed " + std::to_string(seed) +
        ", scored on every " + std::to_string(scored_every_px) + " px";
    std::vector<Row> rows;
    std::string scoring;
    std::optional<ClassifierModel> model_of_all;
    if (!tests.empty() || hold_out_frames) {
      const ClassifierModel& model = model_of_all.emplace(all.train(options, ""));
      if (hold_out_frames) {
        scoring = "held-out frames (every 5th)";
        const ResidueClassifier classifier(model, scored_every_px);
        Scores scores;
        for (const RegisteredFrame& frame : held_out) {
          if (const auto scored = tilth::train_segmenter::score_frame(classifier, frame)) {
            scores += *scored;
          }
        }
        rows.push_back({recordings[0] + " (held out)", scores, recordings});
      } else {
        scoring = "test recordings";
        for (const std::string& test : tests) {
          rows.push_back({test, score_recording(test, model), recordings});
        }
      }
    } else {
      scoring = "leave-one-recording-out (each scored by a model trained on the others)";
      const std::vector<Scores> scores = tilth::train_segmenter::leave_one_recording_out(
          sets, options, [&](std::size_t held, const ClassifierModel& model) {
            return score_recording(recordings[held], model);
          });
      for (std::size_t i = 0; i < scores.size(); ++i) {
        std::vector<std::string> others;
        for (std::size_t j = 0; j < recordings.size(); ++j) {
          if (j != i) others.push_back(recordings[j]);
        }
        rows.push_back({recordings[i], scores[i], others});
      }
    }
    const Scores overall = print_rows(scoring, rows);
    if (const auto report = line.value("--report")) {
      write_report(*report, scoring, rows, overall,
                   {{"format", "tilth-train-segmenter-report/1"},
                    {"feature_set", tilth::segmentation::feature_set_id(features)},
                    {"classifier", tilth::segmentation::classifier_kind_name(options.kind)},
                    {"trees", options.trees},
                    {"depth", options.depth},
                    {"samples", samples},
                    {"seed", seed},
                    {"scored_every_px", scored_every_px}});
    }

    ClassifierModel model =
        all.train(options, "trained on " + sources + " (" + std::to_string(all.soil()) +
                               " soil and " + std::to_string(all.residue()) + " residue pixels, " +
                               settings_text + "); " + scoring + ": " + scores_text(overall));
    tilth::segmentation::write_classifier_model(out, model);
    std::cout << model.training << "\n" << out.string() << ": written\n";
    return kExitOk;
  } catch (const std::exception& error) {
    std::cerr << "tilth train-segmenter: " << error.what() << "\n";
    return kExitFailed;
  }
}
