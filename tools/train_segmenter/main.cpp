// `tilth train-segmenter` (the tilth-train-segmenter program): trains the random forest of
// segmentation.pixel_classifier from recordings with ground-truth masks, reports how well
// it does on held-out frames, and writes the model file.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "command_line.h"
#include "commands.h"
#include "framework/graph_session.h"
#include "pixel_classifier/classifier_model.h"
#include "segmenter_training.h"
#include "tilth/error.h"

namespace {

namespace fs = std::filesystem;
using namespace tilth::cli;
using tilth::train_segmenter::HeldOutPixels;
using tilth::train_segmenter::RegisteredFrames;
using tilth::train_segmenter::Scores;
using tilth::train_segmenter::TrainingSet;

constexpr const char* kUsage =
    R"(usage: tilth train-segmenter RECORDING... --out MODEL [OPTIONS]

Trains the pixel classifier of segmentation.pixel_classifier (a random forest over each
pixel's colour features) on recordings with ground-truth residue masks, scores it on
held-out frames, and writes MODEL (OpenCV YAML; .yml.gz compresses it).

Each RECORDING is an image-folder recording (a folder) or an MCAP file. Frames go
through depth projection and registration as in graphs/measurement-chain.json, so the
classifier sees the colours the stage will see; frames without a mask are skipped.

  --calibration FILE   a rig calibration overriding the one each recording carries
                       (a warning names what differs; default: each recording's own)
  --out MODEL          the model file to write (required)
  --test RECORDING     score on this recording instead (repeatable); without --test,
                       every 5th frame of the training recordings is held out
  --samples N          pixels drawn per frame and class (default 2000)
  --seed N             seed of the draw (default 1): the same inputs and seed give the
                       same model
  --trees N            trees in the forest (default 50)
  --depth N            deepest tree level (default 12)
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

std::string percent(double share) {
  char text[16];
  std::snprintf(text, sizeof text, "%.2f %%", 100 * share);
  return text;
}

std::string scores_text(const Scores& scores) {
  return "accuracy " + percent(scores.accuracy) + ", residue IoU " + percent(scores.residue_iou) +
         ", precision " + percent(scores.precision) + ", recall " + percent(scores.recall) +
         " over " + std::to_string(scores.pixels) + " pixels";
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<CommandLine> parsed;
  try {
    parsed.emplace(argc, argv, 1,
                   std::set<std::string>{"--calibration", "--out", "--test", "--samples", "--seed",
                                         "--trees", "--depth"},
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
  std::uint64_t samples = 0, seed = 0, trees = 0, depth = 0;
  try {
    // A frame has 300 000 pixels; OpenCV caps a tree's depth at 25 levels; 10 000 trees
    // take hours to train.
    samples = line.count("--samples", 1, 1'000'000).value_or(2000);
    seed = line.count("--seed", 1, std::numeric_limits<std::uint32_t>::max()).value_or(1);
    trees = line.count("--trees", 1, 10'000).value_or(50);
    depth = line.count("--depth", 1, 25).value_or(12);
  } catch (const tilth::Error& error) {
    return usage_error(error.what());
  }
  const fs::path calibration = line.value("--calibration").value_or("");
  const fs::path out = *line.value("--out");
  const std::vector<std::string> tests = line.values("--test");

  try {
    const auto registry = tilth::load_plugins(".");
    TrainingSet training;
    HeldOutPixels held_out;
    std::uint64_t draw = 0;
    std::string sources;
    for (const std::string& recording : line.positional()) {
      RegisteredFrames frames = open_recording(*registry, recording, calibration);
      std::uint64_t used = 0, kept_out = 0, unlabelled = 0, position = 0;
      while (const auto frame = frames.next()) {
        const bool hold_out = tests.empty() && position++ % kHoldOutEvery == kHoldOutEvery - 1;
        const bool labelled = hold_out ? held_out.add(*frame)
                                       : training.sample(*frame, static_cast<std::size_t>(samples),
                                                         seed * 1'000'003 + draw++);
        (labelled ? (hold_out ? kept_out : used) : unlabelled) += 1;
      }
      std::cout << recording << ": " << used << " frames for training, " << kept_out
                << " held out, " << unlabelled << " without a mask\n";
      sources += (sources.empty() ? "" : ", ") + recording;
    }
    for (const std::string& recording : tests) {
      RegisteredFrames frames = open_recording(*registry, recording, calibration);
      std::uint64_t scored = 0, unlabelled = 0;
      while (const auto frame = frames.next()) (held_out.add(*frame) ? scored : unlabelled) += 1;
      std::cout << recording << ": " << scored << " frames held out, " << unlabelled
                << " without a mask\n";
    }

    const auto forest = training.train(static_cast<int>(trees), static_cast<int>(depth));
    const auto residue_by_cell = tilth::segmentation::residue_by_cell(*forest);
    std::string summary =
        "trained on " + sources + " (" + std::to_string(training.soil()) + " soil and " +
        std::to_string(training.residue()) + " residue pixels, seed " + std::to_string(seed) +
        ", " + std::to_string(trees) + " trees of depth <= " + std::to_string(depth) + ")";
    if (held_out.pixels() > 0) {
      summary += "; held out: " + scores_text(held_out.score(residue_by_cell));
    } else {
      summary += "; no held-out frames with a mask";
    }
    tilth::segmentation::write_classifier_model(out, *forest, summary);
    std::cout << summary << "\n" << out.string() << ": written\n";
    return kExitOk;
  } catch (const std::exception& error) {
    std::cerr << "tilth train-segmenter: " << error.what() << "\n";
    return kExitFailed;
  }
}
