#include "cnn_training.h"

#include <stdlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <optional>
#include <utility>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "child_process.h"
#include "framework/install_layout.h"
#include "label_tally.h"
#include "tilth/error.h"
#include "tilth/messages/residue_mask.h"

namespace tilth::train_segmenter {
namespace {

namespace fs = std::filesystem;

// Debian's python3, which python3-torch installs into.
constexpr const char* kPython = "/usr/bin/python3";
constexpr int kExitTorchMissing = 3;  // train_cnn.py's
// With one recording, every 5th frame is held out, as for the pixel classifier.
constexpr std::uint64_t kHoldOutEvery = 5;

// A folder of its own under the system's temporary folder, removed with what it holds.
class TemporaryFolder {
 public:
  TemporaryFolder() {
    std::string pattern = (fs::temp_directory_path() / "tilth-train-cnn-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw Error("cannot make a temporary folder " + pattern + ": " + std::strerror(errno));
    }
    path_ = pattern;
  }
  ~TemporaryFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  TemporaryFolder(const TemporaryFolder&) = delete;
  TemporaryFolder& operator=(const TemporaryFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// NNNNNN.color.png (the registered colour) and NNNNNN.labels.png (`labels`: the truth or
// depth labels, 128 where the colour is not trusted), as train_cnn.py reads them.
void write_frame(const RegisteredFrame& frame, cv::Mat labels, const fs::path& folder,
                 std::size_t index) {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu", index);
  labels.setTo(ResidueMask::kUnknown, frame.color->status != RegisteredColor::kValid);
  const fs::path colour = folder / (std::string(name) + ".color.png");
  if (!cv::imwrite(colour.string(), frame.color->bgr) ||
      !cv::imwrite((folder / (std::string(name) + ".labels.png")).string(), labels)) {
    throw Error("cannot write the training frame " + colour.string());
  }
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const auto& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

// train_cnn.py on `folders`, writing `out` and its sidecar.
void run_training(const std::vector<fs::path>& folders, const fs::path& out,
                  const CnnOptions& options, const std::string& training) {
  const fs::path script = shipped_data_dir() / "train-segmenter" / "train_cnn.py";
  std::vector<std::string> argv{kPython, script.string(), "--frames"};
  for (const fs::path& folder : folders) argv.push_back(folder.string());
  argv.insert(argv.end(), {"--out", out.string(), "--seed", std::to_string(options.seed),
                           "--epochs", std::to_string(options.epochs), "--steps",
                           std::to_string(options.steps), "--training", training});
  if (options.input) {
    argv.insert(argv.end(), {"--width", std::to_string(options.input->width), "--height",
                             std::to_string(options.input->height)});
  }
  if (options.input_scale)
    argv.insert(argv.end(), {"--scale", std::to_string(*options.input_scale)});
  if (options.channels) {
    const auto& [a, b, c] = *options.channels;
    argv.insert(argv.end(), {"--channels", std::to_string(a) + "," + std::to_string(b) + "," +
                                               std::to_string(c)});
  }
  const ChildResult result = run_child(argv, "  train_cnn.py: ");
  if (result.exit_code == kExitTorchMissing) {
    throw Error(
        "the CNN's training needs PyTorch: install python3-torch, python3-torchvision "
        "and python3-onnx (tools/setup.sh); " +
        script.string() + " said:\n" + result.last_lines);
  }
  if (result.exit_code != 0) {
    throw Error("the CNN's training (" + std::string(kPython) + " " + script.string() +
                ") failed with exit code " + std::to_string(result.exit_code) +
                "; its last lines:\n" + result.last_lines);
  }
}

// Appends `text` to the sidecar's "training".
void add_to_training_text(const fs::path& onnx, const std::string& text) {
  const fs::path file = segmentation::cnn_sidecar_path(onnx);
  nlohmann::json sidecar;
  {
    std::ifstream in(file);
    sidecar = nlohmann::json::parse(in);
  }
  sidecar["training"] = sidecar.value("training", "") + "; " + text;
  std::ofstream out(file);
  out << sidecar.dump(2) << "\n";
  if (!out) throw Error("model sidecar '" + file.string() + "' cannot be written");
}

std::string scores_text(const Scores& scores) {
  char text[128];
  std::snprintf(text, sizeof text, "residue IoU %.3f, precision %.3f, recall %.3f",
                scores.residue_iou(), scores.precision(), scores.recall());
  return text;
}

// The scores of every frame with a mask of `frames`.
template <typename Next>
std::pair<Scores, std::uint64_t> score_frames(segmentation::ResidueNet& net, Next next) {
  std::pair<Scores, std::uint64_t> total;
  while (const auto frame = next()) {
    if (const auto scores = score_cnn_frame(net, *frame)) {
      total.first += *scores;
      ++total.second;
    }
  }
  return total;
}

}  // namespace

void classify_frame(segmentation::ResidueNet& net, const cv::Mat& bgr, cv::Mat& residue) {
  const auto& sidecar = net.sidecar();
  const int width =
      std::min(bgr.cols, static_cast<int>(sidecar.width / sidecar.window_scale + 0.5));
  const int height =
      std::min(bgr.rows, static_cast<int>(sidecar.height / sidecar.window_scale + 0.5));
  residue.create(bgr.size(), CV_8UC1);
  cv::Mat window;
  for (int y = 0;; y += height) {
    const int top = std::min(y, bgr.rows - height);
    for (int x = 0;; x += width) {
      const int left = std::min(x, bgr.cols - width);
      const cv::Rect area(left, top, width, height);
      net.classify(bgr(area), window);
      window.copyTo(residue(area));
      if (left + width >= bgr.cols) break;
    }
    if (top + height >= bgr.rows) break;
  }
}

std::optional<Scores> score_cnn_frame(segmentation::ResidueNet& net, const RegisteredFrame& frame) {
  const cv::Mat& truth = frame.truth->residue_mask;
  if (truth.empty()) return std::nullopt;
  thread_local cv::Mat residue;
  classify_frame(net, frame.color->bgr, residue);
  return score_mask(residue, truth, frame.color->status == RegisteredColor::kValid);
}

CnnTraining train_cnn(const std::vector<std::string>& recordings,
                      const std::vector<std::string>& tests, const OpenRecording& open,
                      const CnnOptions& options, const fs::path& out) {
  if (out.extension() != ".onnx") {
    throw Error("--out " + out.string() +
                ": expected a file name ending in .onnx (the sidecar "
                "goes beside it with .json)");
  }
  const TemporaryFolder temporary;
  const bool hold_out_frames = tests.empty() && recordings.size() == 1;
  std::optional<segmentation::DepthLabels> labeller;
  if (options.depth_labels) labeller.emplace(*options.depth_labels);
  std::vector<fs::path> folders;
  std::vector<RegisteredFrame> held_out;
  cv::Mat labels;
  for (std::size_t i = 0; i < recordings.size(); ++i) {
    folders.push_back(temporary.path() / std::to_string(i));
    fs::create_directory(folders.back());
    RegisteredFrames frames = open(recordings[i]);
    std::size_t written = 0, position = 0, unlabelled = 0;
    LabelTally tally;
    while (auto frame = frames.next()) {
      if (!labeller && frame->truth->residue_mask.empty()) {
        ++unlabelled;
      } else if (hold_out_frames && position++ % kHoldOutEvery == kHoldOutEvery - 1) {
        held_out.push_back(std::move(*frame));
      } else if (labeller) {
        labeller->label(frame->depth->mm, labels);
        tally += tally_labels(labels, *frame);
        write_frame(*frame, labels, folders.back(), written++);
      } else {
        write_frame(*frame, frame->truth->residue_mask.clone(), folders.back(), written++);
      }
    }
    if (labeller && tally.labelled() == 0) {
      throw Error("recording '" + recordings[i] + "': depth labels no pixel of its " +
                  std::to_string(written) + " training frames (" +
                  depth_labels_text(*options.depth_labels) + ")");
    }
    if (written == 0) {
      throw Error("recording '" + recordings[i] + "': no frame with a mask to train on (" +
                  std::to_string(unlabelled) + " without one; --model cnn trains on masks)");
    }
    std::cout << recordings[i] << ": " << written << " frames for training, " << held_out.size()
              << " held out, "
              << (labeller ? tally_text(tally) : std::to_string(unlabelled) + " without a mask")
              << "\n";
  }

  CnnTraining training;
  auto score_recording = [&](const std::string& recording, segmentation::ResidueNet& net) {
    RegisteredFrames frames = open(recording);
    return score_frames(net, [&] { return frames.next(); });
  };
  const std::string sources =
      "trained on " + joined(recordings) +
      (labeller ? " labelled by depth (" + depth_labels_text(*options.depth_labels) + ")" : "");
  if (!tests.empty() || hold_out_frames) {
    run_training(folders, out, options, sources);
    segmentation::ResidueNet net(out);
    if (hold_out_frames) {
      training.scoring = "held-out frames (every 5th)";
      std::size_t next = 0;
      const auto [scores, scored] = score_frames(net, [&]() -> std::optional<RegisteredFrame> {
        if (next == held_out.size()) return std::nullopt;
        return held_out[next++];
      });
      training.rows.push_back({recordings[0] + " (held out)", scores, scored, recordings});
    } else {
      training.scoring = "test recordings";
      for (const std::string& test : tests) {
        const auto [scores, scored] = score_recording(test, net);
        training.rows.push_back({test, scores, scored, recordings});
      }
    }
  } else if (options.leave_one_out) {
    training.scoring = "leave-one-recording-out (each scored by a model trained on the others)";
    for (std::size_t held = 0; held < recordings.size(); ++held) {
      std::vector<fs::path> others;
      std::vector<std::string> names;
      for (std::size_t i = 0; i < recordings.size(); ++i) {
        if (i == held) continue;
        others.push_back(folders[i]);
        names.push_back(recordings[i]);
      }
      std::cout << "without " << recordings[held] << ":\n";
      const fs::path fold = temporary.path() / ("fold-" + std::to_string(held) + ".onnx");
      run_training(others, fold, options, "trained on " + joined(names));
      segmentation::ResidueNet net(fold);
      const auto [scores, scored] = score_recording(recordings[held], net);
      training.rows.push_back({recordings[held], scores, scored, names});
    }
    std::cout << "on every recording:\n";
    run_training(folders, out, options, sources);
  } else {
    training.scoring = "not scored (--no-leave-one-out)";
    run_training(folders, out, options, sources);
  }
  // The model is one the stage can run.
  segmentation::ResidueNet written(out);
  Scores overall;
  std::uint64_t scored = 0;
  for (const CnnScoredRecording& row : training.rows) {
    overall += row.scores;
    scored += row.scored_frames;
  }
  add_to_training_text(out, training.rows.empty() ? training.scoring
                                                  : training.scoring + ": " +
                                                        (scored == 0 ? "no mask to score against"
                                                                     : scores_text(overall)));
  return training;
}

}  // namespace tilth::train_segmenter
