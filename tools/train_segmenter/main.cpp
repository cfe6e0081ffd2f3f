// `tilth train-segmenter` (the tilth-train-segmenter program): trains the classifier of
// segmentation.pixel_classifier from recordings with ground-truth masks, or from the pixels
// their depth labels (--labels depth), reports how well it does where it was not trained
// (other recordings, or held-out frames), and writes the model file.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core/mat.hpp>

#include "cnn_training.h"
#include "command_line.h"
#include "commands.h"
#include "framework/graph_session.h"
#include "label_tally.h"
#include "leave_one_out.h"
#include "pixel_classifier/classifier_model.h"
#include "segmenter_training.h"
#include "soil_surface/depth_labels.h"
#include "tilth/error.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;
using tilth::segmentation::ClassifierModel;
using tilth::segmentation::DepthLabelOptions;
using tilth::segmentation::DepthLabels;
using tilth::segmentation::FeatureSet;
using tilth::segmentation::ResidueClassifier;
using tilth::train_segmenter::ClassifierOptions;
using tilth::train_segmenter::depth_labels_text;
using tilth::train_segmenter::LabelTally;
using tilth::train_segmenter::RegisteredFrame;
using tilth::train_segmenter::RegisteredFrames;
using tilth::train_segmenter::Scores;
using tilth::train_segmenter::tally_text;
using tilth::train_segmenter::TrainingSet;

constexpr const char* kUsage =
    R"(usage: tilth train-segmenter RECORDING... --out MODEL [OPTIONS]

Trains the pixel classifier of segmentation.pixel_classifier (a random forest or boosted
trees over each pixel's colour and texture features) on recordings with ground-truth
residue masks, or on unlabelled recordings with --labels depth, scores it where it was
not trained, and writes MODEL (OpenCV YAML; .yml.gz compresses it).

Each RECORDING is an image-folder recording (a folder) or an MCAP file. Frames go
through depth projection and registration as in graphs/measurement-chain.json, so the
classifier sees the colours the stage will see.

Scoring: with --test, on those recordings; else, with several RECORDINGs, leave one
recording out (each scored by a model trained on the others); with one, on every 5th
frame, held out. IoU, precision and recall of residue per recording and overall (pixels
pooled), against the recordings' masks whatever the labels (a recording without one is
not scored); MODEL is then trained on every RECORDING.

  --calibration FILE   a rig calibration overriding the one each recording carries
                       (a warning names what differs; default: each recording's own)
  --out MODEL          the model file to write (required)
  --test RECORDING     score on this recording instead (repeatable)
  --labels SOURCE      mask (default): each frame's ground-truth mask, frames without
                       one skipped; depth: the pixels whose depth labels them, residue
                       standing clearly above the soil surface fitted to the frame's
                       depth and soil on it, the band between and each class's edge
                       unlabelled; masks are then read only to score
  --soil-within-mm MM  depth labels: soil lies within MM of the surface (default 1.5)
  --residue-above-mm MM
                       depth labels: residue stands more than MM above it (default 4)
  --edge-px N          depth labels: neither class within N px of the other or the
                       band between (default 1)
  --envelope-px N      depth labels: the surface from the depths' envelope over N px, as
                       segmentation.depth_aided's envelope_px, for ridges and steps
                       (default 0: a plane)
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

--model cnn trains segmentation.cnn's network instead: a small U-Net (PyTorch, Debian's
python3-torch) on the same frames and masks (or depth labels), written as MODEL (.onnx)
and its sidecar MODEL.json (the stage's input preparation), scored by the stage's own
code. The options of the trees (--features, --classifier, --samples, --trees, --depth,
--scored-every) are the pixel classifier's.
  --model KIND         pixel_classifier (default) or cnn
  --epochs N           cnn: training epochs (default 30)
  --steps N            cnn: batches of 8 windows per epoch (default 40)
  --input WxH          cnn: the network's input in px, multiples of 4 (default 84x64);
                       smaller runs faster
  --input-scale S      cnn: network px per depth px (default 0.25): the window segmented
                       at once is W/S x H/S depth px
  --channels A,B,C     cnn: the U-Net's channels at its three levels (default 16,32,64)
  --no-leave-one-out   cnn: with several RECORDINGs and no --test, train once and do
                       not score (each left-out recording costs a training)
)";

constexpr std::uint64_t kHoldOutEvery = 5;

// The options only --labels depth reads.
const std::set<std::string> kDepthLabelOptions = {"--soil-within-mm", "--residue-above-mm",
                                                  "--edge-px", "--envelope-px"};

int usage_error(const std::string& message) {
  std::cerr << "tilth train-segmenter: " << message << "\n\n" << kUsage;
  return kExitUsage;
}

// --labels and the options of --labels depth: the depth labels' settings, or none for
// masks. Throws tilth::Error naming an option that does not fit.
std::optional<DepthLabelOptions> depth_label_options(const CommandLine& line) {
  const std::string labels = line.value("--labels").value_or("mask");
  if (labels != "mask" && labels != "depth") {
    throw tilth::Error("--labels \"" + labels + "\" (expected mask or depth)");
  }
  for (const std::string& option : kDepthLabelOptions) {
    if (labels != "depth" && line.value(option)) {
      throw tilth::Error(option + " is an option of --labels depth (labels: " + labels + ")");
    }
  }
  if (labels != "depth") return std::nullopt;
  DepthLabelOptions options;
  options.soil_within_mm = line.real("--soil-within-mm", 0.1, 50).value_or(options.soil_within_mm);
  options.residue_above_mm =
      line.real("--residue-above-mm", 0.2, 500).value_or(options.residue_above_mm);
  options.edge_px = static_cast<int>(line.count("--edge-px", 0, 20).value_or(options.edge_px));
  options.envelope_px = line.real("--envelope-px", 0, 400).value_or(options.envelope_px);
  return options;
}

// The report's "depth_labels": the settings, or null for masks.
nlohmann::json depth_labels_json(const std::optional<DepthLabelOptions>& options) {
  if (!options) return nullptr;
  return {{"soil_within_mm", options->soil_within_mm},
          {"residue_above_mm", options->residue_above_mm},
          {"edge_px", options->edge_px},
          {"envelope_px", options->envelope_px}};
}

// --input WxH: multiples of 4 (two poolings) from 8 to 1024.
cv::Size network_input(const std::string& text) {
  int width = 0, height = 0;
  char end = 0;
  const bool parsed = std::sscanf(text.c_str(), "%dx%d%c", &width, &height, &end) == 2;
  if (!parsed || width % 4 != 0 || height % 4 != 0 || std::min(width, height) < 8 ||
      std::max(width, height) > 1024) {
    throw tilth::Error("--input '" + text +
                       "': expected WIDTHxHEIGHT in px, each a multiple of 4 from 8 to 1024 "
                       "(the network pools twice), e.g. 84x64");
  }
  return {width, height};
}

// --channels A,B,C: three counts from 1 to 512.
std::array<int, 3> unet_channels(const std::string& text) {
  std::array<int, 3> channels{};
  char end = 0;
  const bool parsed =
      std::sscanf(text.c_str(), "%d,%d,%d%c", &channels[0], &channels[1], &channels[2], &end) == 3;
  if (!parsed || *std::min_element(channels.begin(), channels.end()) < 1 ||
      *std::max_element(channels.begin(), channels.end()) > 512) {
    throw tilth::Error("--channels '" + text +
                       "': expected three channel counts from 1 to 512, e.g. 16,32,64");
  }
  return channels;
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
  std::uint64_t scored_frames = 0;  // frames with a mask; 0: the recording is not scored
  std::vector<std::string> trained_on;
};

constexpr const char* kNoMask = "no mask to score against";

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

// The table of rows and the pooled overall of the scored ones; returns the pooled scores,
// empty when no row is scored.
std::optional<Scores> print_rows(const std::string& scoring, const std::vector<Row>& rows) {
  std::size_t width = 7;
  for (const Row& row : rows) width = std::max(width, row.recording.size());
  auto line = [&](const std::string& name, const Scores& scores) {
    std::cout << "  " << name << std::string(width - name.size() + 2, ' ')
              << number("%5.3f", scores.residue_iou()) << "  "
              << number("%9.3f", scores.precision()) << "  " << number("%6.3f", scores.recall())
              << "  " << number("%8.3f", scores.accuracy()) << "  " << scores.pixels() << "\n";
  };
  std::cout << scoring << ":\n  recording" << std::string(width - 5, ' ')
            << "IoU  precision  recall  accuracy  pixels\n";
  Scores overall;
  double iou_sum = 0;
  std::size_t scored = 0;
  for (const Row& row : rows) {
    if (row.scored_frames == 0) {
      std::cout << "  " << row.recording << std::string(width - row.recording.size() + 2, ' ')
                << kNoMask << "\n";
      continue;
    }
    line(row.recording, row.scores);
    overall += row.scores;
    iou_sum += row.scores.residue_iou();
    ++scored;
  }
  if (scored == 0) {
    std::cout << "  nothing scored: no recording has a mask\n";
    return std::nullopt;
  }
  line("overall", overall);
  std::cout << "  mean IoU of the recordings scored (" << scored << " of " << rows.size()
            << "): " << number("%.3f", iou_sum / static_cast<double>(scored)) << "\n";
  return overall;
}

// A row not scored has "scored": false and no scores; with none scored, "overall" and
// "mean_iou" are null.
void write_report(const fs::path& file, const std::string& scoring, const std::vector<Row>& rows,
                  const std::optional<Scores>& overall, const nlohmann::json& settings) {
  nlohmann::json report = settings;
  report["scoring"] = scoring;
  report["recordings"] = nlohmann::json::array();
  double iou_sum = 0;
  std::size_t scored = 0;
  for (const Row& row : rows) {
    nlohmann::json entry =
        row.scored_frames == 0 ? nlohmann::json::object() : scores_json(row.scores);
    entry["recording"] = row.recording;
    entry["scored"] = row.scored_frames != 0;
    entry["trained_on"] = row.trained_on;
    report["recordings"].push_back(entry);
    if (row.scored_frames != 0) {
      iou_sum += row.scores.residue_iou();
      ++scored;
    }
  }
  report["overall"] = overall ? scores_json(*overall) : nlohmann::json();
  report["mean_iou"] =
      scored == 0 ? nlohmann::json() : nlohmann::json(iou_sum / static_cast<double>(scored));
  std::ofstream out(file);
  out << report.dump(2) << "\n";
  if (!out) throw tilth::Error("report '" + file.string() + "' cannot be written");
}

// tilth train-segmenter --model cnn.
int train_cnn_command(const CommandLine& line) {
  tilth::train_segmenter::CnnOptions options;
  try {
    for (const std::string option :
         {"--features", "--classifier", "--samples", "--trees", "--depth", "--scored-every"}) {
      if (line.value(option)) throw tilth::Error(option + " is an option of the pixel classifier");
    }
    options.depth_labels = depth_label_options(line);
    options.seed =
        line.count("--seed", 1, std::numeric_limits<std::uint32_t>::max()).value_or(options.seed);
    options.epochs = static_cast<int>(line.count("--epochs", 1, 10'000).value_or(options.epochs));
    options.steps = static_cast<int>(line.count("--steps", 1, 100'000).value_or(options.steps));
    options.leave_one_out = !line.flag("--no-leave-one-out");
    if (const auto input = line.value("--input")) options.input = network_input(*input);
    options.input_scale = line.real("--input-scale", 0.02, 1);
    if (const auto channels = line.value("--channels")) options.channels = unet_channels(*channels);
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const fs::path calibration = line.value("--calibration").value_or("");
  const fs::path out = *line.value("--out");
  try {
    const auto registry = tilth::load_plugins(".");
    const tilth::train_segmenter::CnnTraining training = tilth::train_segmenter::train_cnn(
        line.positional(), line.values("--test"),
        [&](const std::string& recording) {
          return open_recording(*registry, recording, calibration);
        },
        options, out);
    std::vector<Row> rows;
    for (const auto& row : training.rows) {
      rows.push_back({row.recording, row.scores, row.scored_frames, row.trained_on});
    }
    std::optional<Scores> overall;
    if (rows.empty()) {
      std::cout << training.scoring << "\n";
    } else {
      overall = print_rows(training.scoring, rows);
    }
    if (const auto report = line.value("--report")) {
      write_report(*report, training.scoring, rows, overall,
                   {{"format", "tilth-train-segmenter-report/1"},
                    {"model", "cnn"},
                    {"labels", options.depth_labels ? "depth" : "mask"},
                    {"depth_labels", depth_labels_json(options.depth_labels)},
                    {"epochs", options.epochs},
                    {"steps", options.steps},
                    {"seed", options.seed}});
    }
    std::cout << out.string() << " and " << tilth::segmentation::cnn_sidecar_path(out).string()
              << ": written\n";
    return kExitOk;
  } catch (const std::exception& error) {
    std::cerr << "tilth train-segmenter: " << error.what() << "\n";
    return kExitFailed;
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1, std::set<std::string>{"--calibration",    "--out",
                                                        "--test",           "--samples",
                                                        "--seed",           "--trees",
                                                        "--depth",          "--features",
                                                        "--classifier",     "--report",
                                                        "--scored-every",   "--labels",
                                                        "--soil-within-mm", "--residue-above-mm",
                                                        "--edge-px",        "--envelope-px",
                                                        "--model",          "--epochs",
                                                        "--steps",          "--input",
                                                        "--input-scale",    "--channels"},
                   std::set<std::string>{"--help", "--no-leave-one-out"});
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
  const std::string model_kind = line.value("--model").value_or("pixel_classifier");
  if (model_kind == "cnn") return train_cnn_command(line);
  if (model_kind != "pixel_classifier") {
    return usage_error("--model \"" + model_kind + "\" (expected pixel_classifier or cnn)");
  }
  for (const std::string option :
       {"--epochs", "--steps", "--no-leave-one-out", "--input", "--input-scale", "--channels"}) {
    if (line.value(option) || line.flag(option)) {
      return usage_error(option + " is an option of --model cnn");
    }
  }
  std::uint64_t samples = 0, seed = 0;
  int scored_every_px = tilth::segmentation::kScoredEveryPx;
  ClassifierOptions options;
  FeatureSet features = FeatureSet::kTexture;
  std::optional<DepthLabelOptions> depth_options;
  std::optional<DepthLabels> labeller;
  try {
    depth_options = depth_label_options(line);
    if (depth_options) labeller.emplace(*depth_options);
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
    cv::Mat labels;
    for (const std::string& recording : recordings) {
      sets.emplace_back(features);
      RegisteredFrames frames = open_recording(*registry, recording, calibration);
      std::uint64_t used = 0, kept_out = 0, unlabelled = 0, position = 0;
      LabelTally tally;
      while (auto frame = frames.next()) {
        if (!labeller && frame->truth->residue_mask.empty()) {
          ++unlabelled;
        } else if (hold_out_frames && position++ % kHoldOutEvery == kHoldOutEvery - 1) {
          held_out.push_back(std::move(*frame));
          ++kept_out;
        } else if (labeller) {
          labeller->label(frame->depth->mm, labels);
          tally += tilth::train_segmenter::tally_labels(labels, *frame);
          sets.back().sample(*frame, labels, static_cast<std::size_t>(samples),
                             seed * 1'000'003 + draw++);
          ++used;
        } else {
          sets.back().sample(*frame, static_cast<std::size_t>(samples), seed * 1'000'003 + draw++);
          ++used;
        }
      }
      if (labeller && tally.labelled() == 0) {
        throw tilth::Error(
            "recording '" + recording + "': depth labels no pixel of its " + std::to_string(used) +
            " training frames (" + std::to_string(tally.pixels) +
            " of their pixels have trusted colour; expected pixels with depth, soil within " +
            number("%g", depth_options->soil_within_mm) +
            " mm of the surface fitted to it or residue more than " +
            number("%g", depth_options->residue_above_mm) + " mm above it)");
      }
      std::cout << recording << ": " << used << " frames for training, " << kept_out
                << " held out, ";
      if (labeller) {
        std::cout << tally_text(tally) << "\n";
      } else {
        std::cout << unlabelled << " without a mask\n";
      }
    }
    // The scores of a recording and how many of its frames have a mask to score against.
    auto score_recording = [&](const std::string& recording, const ClassifierModel& model) {
      const ResidueClassifier classifier(model, scored_every_px);
      RegisteredFrames frames = open_recording(*registry, recording, calibration);
      std::pair<Scores, std::uint64_t> scores;
      while (const auto frame = frames.next()) {
        if (const auto scored = tilth::train_segmenter::score_frame(classifier, *frame)) {
          scores.first += *scored;
          ++scores.second;
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
        (labeller ? "labelled by depth (" + depth_labels_text(*depth_options) + "), "
                  : std::string("labelled by masks, ")) +
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
        Row row{recordings[0] + " (held out)", {}, 0, recordings};
        for (const RegisteredFrame& frame : held_out) {
          if (const auto scored = tilth::train_segmenter::score_frame(classifier, frame)) {
            row.scores += *scored;
            ++row.scored_frames;
          }
        }
        rows.push_back(row);
      } else {
        scoring = "test recordings";
        for (const std::string& test : tests) {
          const auto [scores, scored_frames] = score_recording(test, model);
          rows.push_back({test, scores, scored_frames, recordings});
        }
      }
    } else {
      scoring = "leave-one-recording-out (each scored by a model trained on the others)";
      std::vector<std::uint64_t> scored_frames(recordings.size());
      const std::vector<Scores> scores = tilth::train_segmenter::leave_one_recording_out(
          sets, options, [&](std::size_t held, const ClassifierModel& model) {
            const auto [scored, frames] = score_recording(recordings[held], model);
            scored_frames[held] = frames;
            return scored;
          });
      for (std::size_t i = 0; i < scores.size(); ++i) {
        std::vector<std::string> others;
        for (std::size_t j = 0; j < recordings.size(); ++j) {
          if (j != i) others.push_back(recordings[j]);
        }
        rows.push_back({recordings[i], scores[i], scored_frames[i], others});
      }
    }
    const std::optional<Scores> overall = print_rows(scoring, rows);
    if (const auto report = line.value("--report")) {
      write_report(*report, scoring, rows, overall,
                   {{"format", "tilth-train-segmenter-report/1"},
                    {"labels", labeller ? "depth" : "mask"},
                    {"depth_labels", depth_labels_json(depth_options)},
                    {"feature_set", tilth::segmentation::feature_set_id(features)},
                    {"classifier", tilth::segmentation::classifier_kind_name(options.kind)},
                    {"trees", options.trees},
                    {"depth", options.depth},
                    {"samples", samples},
                    {"seed", seed},
                    {"scored_every_px", scored_every_px}});
    }

    ClassifierModel model = all.train(
        options, "trained on " + sources + " (" + std::to_string(all.soil()) + " soil and " +
                     std::to_string(all.residue()) + " residue pixels, " + settings_text + "); " +
                     scoring + ": " + (overall ? scores_text(*overall) : kNoMask));
    tilth::segmentation::write_classifier_model(out, model);
    std::cout << model.training << "\n" << out.string() << ": written\n";
    return kExitOk;
  } catch (const std::exception& error) {
    std::cerr << "tilth train-segmenter: " << error.what() << "\n";
    return kExitFailed;
  }
}
